// atmos reference integration (docs/engine.md, "The reference integration"):
// a minimal OpenGL 3.3 core host that renders one view of a bake written by
// `atmos bake --model NAME -o DIR` into a float framebuffer and writes it as a
// PFM, the same linear radiance `atmos render --load DIR` writes.
//
// It is documentation in code for engine programmers: everything an engine
// needs is here, in the order an engine does it.
//   1. a GL 3.3 core context (EGL, headless: no window, no display server);
//   2. the bake: NAME.json ("raw": each table's size and byte offsets in
//      tables.f32 / tables.f16; "shaders"."order": the GLSL files to concatenate);
//   3. the tables as textures (RGB32F or RGB16F, LINEAR, CLAMP_TO_EDGE; a 3D
//      table's raw layout is exactly what glTexImage3D reads);
//   4. the program: "#version 330 core", the bake's three GLSL files, and a
//      main() that calls atmos_Evaluate per pixel (ShadePixel of `atmos render`);
//   5. per frame, for a model with frame tables (hillaire), the sky-view pass and
//      the 32 aerial-perspective slice passes, then the sky pass;
//   6. readback (rows bottom to top, as PFM stores them);
//   7. with --precompute, instead, the bake's "gpu_precompute" passes: the
//      tables computed on the GPU (docs/engine.md, "Tables computed on the GPU").
// It links the system's libEGL and libOpenGL (glvnd) and nlohmann/json; nothing
// of atmos. Usage: `atmos_gl_host --help`.
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Json = nlohmann::json;

// Exit statuses: 2 bad input or a GL error, 3 no OpenGL 3.3 context here.
constexpr int kExitNoContext = 3;

struct Error : std::runtime_error {
    using std::runtime_error::runtime_error;
};
struct NoContext : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// ---- cameras (double precision, as the C++ Camera of include/atmos/view.h) ----

struct Vec3 {
    double x = 0.0, y = 0.0, z = 0.0;
};
Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double Dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 Cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 Normalize(Vec3 a) { return a * (1.0 / std::sqrt(Dot(a, a))); }
double Radians(double deg) { return deg * 3.14159265358979323846 / 180.0; }

struct Camera {
    Vec3 position;  // metres from the planet's centre
    Vec3 forward, right, up;
    double tan_half_fov_y = 0.0;
};

struct View {
    Camera camera;
    Vec3 sun;                     // unit, toward the sun
    double sun_irradiance = 1.0;  // multiplies the atmosphere's solar irradiance
};

// MakeCamera (src/atmos/harness/views.cpp).
Camera MakeCamera(Vec3 position, Vec3 forward, Vec3 world_up, double vfov_deg) {
    Camera c;
    c.position = position;
    c.forward = Normalize(forward);
    c.right = Normalize(Cross(c.forward, world_up));
    c.up = Cross(c.right, c.forward);
    c.tan_half_fov_y = std::tan(0.5 * Radians(vfov_deg));
    return c;
}

// AzimuthElevation (views.cpp): azimuth from +x toward +y.
Vec3 AzimuthElevation(double az_deg, double el_deg) {
    const double a = Radians(az_deg), e = Radians(el_deg);
    return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

// The 12 standard views of `atmos render --view NAME` (StandardViews,
// src/atmos/harness/views.cpp; docs/views.md), for an atmosphere of radii
// bottom and top. Their sun irradiance is 6 x the atmosphere's.
bool StandardView(const std::string& name, double bottom, double top, View* v) {
    const Vec3 z{0, 0, 1};
    const struct {
        const char* time;
        double sun_elevation;
    } times[] = {{"dawn", -6}, {"sunrise", 6}, {"noon", 90}};
    v->sun_irradiance = 6.0;
    for (const auto& t : times) {
        v->sun = AzimuthElevation(0, t.sun_elevation);
        if (name == std::string("ground-") + t.time || name == std::string("plane-") + t.time) {
            const double altitude = name[0] == 'g' ? 0.0 : 5000.0;
            v->camera = MakeCamera({0, 0, bottom + altitude}, AzimuthElevation(0, 10), z, 60);
            return true;
        }
        if (name == std::string("orbit-") + t.time) {
            v->camera = MakeCamera({-1000e3, 0, bottom + 100e3}, {1, 0, 0}, z, 60);
            return true;
        }
    }
    if (name == "space") {
        v->camera = MakeCamera({0, -3.75 * top, 0}, {0, 1, 0}, z, 40);
        v->sun = Normalize({0.8, -0.3, 0.5});
        return true;
    }
    v->sun = AzimuthElevation(0, -3);
    if (name == "planet-shadow-ground") {
        v->camera = MakeCamera({0, 0, bottom}, AzimuthElevation(150, 10), z, 60);
        return true;
    }
    if (name == "planet-shadow-orbit") {
        v->camera = MakeCamera({0, 0, bottom + 200e3}, AzimuthElevation(150, -12), z, 60);
        return true;
    }
    return false;
}

// "key=value,key=value" -> value of `key` (NaN when absent).
double KeyValue(const std::string& spec, const std::string& key, double fallback) {
    std::stringstream in(spec);
    std::string item;
    while (std::getline(in, item, ',')) {
        const size_t eq = item.find('=');
        if (eq != std::string::npos && item.substr(0, eq) == key) {
            char* end = nullptr;
            const double value = std::strtod(item.c_str() + eq + 1, &end);
            if (*end != '\0' || !std::isfinite(value)) {
                throw Error("invalid " + key + " '" + item.substr(eq + 1) + "'");
            }
            return value;
        }
    }
    return fallback;
}

// The free perspective camera of `atmos render --camera altitude=M,azimuth=DEG,
// elevation=DEG,roll=DEG,fov=DEG --sun elevation=DEG,azimuth=DEG`
// (MakeCameraFromSpec, ParseSunSpec in src/atmos/harness/camera_spec.cpp):
// azimuths clockwise from north (+y), east +x; sun irradiance 1 x the atmosphere's.
View FreeView(const std::string& camera, const std::string& sun, double bottom) {
    const double a = Radians(KeyValue(camera, "azimuth", 0.0));
    const double e = Radians(KeyValue(camera, "elevation", 0.0));
    const double roll = Radians(KeyValue(camera, "roll", 0.0));
    const double fov = KeyValue(camera, "fov", 60.0);
    if (!(fov > 0.0 && fov < 180.0)) throw Error("--camera fov must be in (0, 180) degrees");
    const Vec3 horizontal{std::sin(a), std::cos(a), 0.0}, zenith{0, 0, 1};
    const Vec3 forward = horizontal * std::cos(e) + zenith * std::sin(e);
    const Vec3 up = zenith * std::cos(e) - horizontal * std::sin(e);
    const Vec3 right = Cross(forward, up);
    View v;
    v.camera.position = {0, 0, bottom + KeyValue(camera, "altitude", 0.0)};
    v.camera.forward = Normalize(forward);
    v.camera.right = Normalize(right * std::cos(roll) - up * std::sin(roll));
    v.camera.up = Normalize(up * std::cos(roll) + right * std::sin(roll));
    v.camera.tan_half_fov_y = std::tan(0.5 * Radians(fov));
    const double sun_el = Radians(KeyValue(sun, "elevation", NAN));
    if (std::isnan(sun_el)) throw Error("--sun needs elevation=DEG");
    const double sun_az = Radians(KeyValue(sun, "azimuth", 0.0));
    v.sun = {std::cos(sun_el) * std::sin(sun_az), std::cos(sun_el) * std::cos(sun_az),
             std::sin(sun_el)};
    v.sun_irradiance = 1.0;
    return v;
}

// ---- 1. the context: EGL, headless ----

// An OpenGL 3.3 core context without a window. Mesa's EGL offers the
// "surfaceless" platform (EGL_MESA_platform_surfaceless), which needs no X
// server, no GPU and no /dev/dri (it falls back to llvmpipe, the CPU);
// elsewhere the default display and a 1 x 1 pbuffer. The host renders into its
// own framebuffer objects, so the surface is never drawn to.
void CreateContext() {
    EGLDisplay display = EGL_NO_DISPLAY;
    const char* extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (extensions && std::strstr(extensions, "EGL_MESA_platform_surfaceless")) {
        auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
            eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (get_platform_display) {
            display =
                get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        }
    }
    if (display == EGL_NO_DISPLAY) display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
        throw NoContext("no EGL display (eglInitialize failed)");
    }
    if (!eglBindAPI(EGL_OPENGL_API)) throw NoContext("EGL has no desktop OpenGL API");
    const bool surfaceless =
        std::strstr(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context");
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE, surfaceless ? 0 : EGL_PBUFFER_BIT,
                                     EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config;
    EGLint count = 0;
    if (!eglChooseConfig(display, config_attribs, &config, 1, &count) || count < 1) {
        throw NoContext("no EGL config with desktop OpenGL");
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                      3,
                                      EGL_CONTEXT_MINOR_VERSION,
                                      3,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
    if (context == EGL_NO_CONTEXT) throw NoContext("no OpenGL 3.3 core context");
    EGLSurface surface = EGL_NO_SURFACE;
    if (!surfaceless) {
        const EGLint pbuffer_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        surface = eglCreatePbufferSurface(display, config, pbuffer_attribs);
    }
    if (!eglMakeCurrent(display, surface, surface, context)) {
        throw NoContext("eglMakeCurrent failed");
    }
}

void CheckGl(const char* where) {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        char text[96];
        std::snprintf(text, sizeof text, "OpenGL error 0x%04x in %s", e, where);
        throw Error(text);
    }
}

// ---- 2. the bake ----

std::string ReadFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot read '" + path + "'");
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

struct Bake {
    Json json;          // NAME.json
    std::string blob;   // tables.f32 or tables.f16
    bool half = false;  // blob holds IEEE binary16
    std::string glsl;   // the "order" files concatenated
};

// The bake's NAME.json is the JSON file of DIR with "model", "raw" and
// "shaders" (DIR may also hold tables_rgba.json, which has no "shaders").
Bake LoadBake(const std::string& dir, bool half) {
    Bake b;
    std::error_code error;
    for (const auto& file : std::filesystem::directory_iterator(dir, error)) {
        if (file.path().extension() != ".json") continue;
        Json j = Json::parse(ReadFile(file.path().string()), nullptr, false);
        if (j.is_object() && j.contains("model") && j.contains("raw") && j.contains("shaders")) {
            b.json = std::move(j);
            break;
        }
    }
    if (b.json.is_null()) throw Error("no bake in '" + dir + "' (atmos bake --model NAME -o DIR)");
    b.half = half;
    b.blob = ReadFile(dir + "/" +
                      b.json["raw"][half ? "float16" : "float32"]["file"].get<std::string>());
    for (const Json& file : b.json["shaders"]["order"]) {
        b.glsl += ReadFile(dir + "/" + file.get<std::string>()) + "\n";
    }
    return b;
}

// ---- 3. the tables as textures ----

// A table of the raw blob ("raw"."tables"."NAME": width, height, depth,
// channels, byte offsets) as a texture. The blob's order (channel fastest,
// then x = u, y = v, z = layer; row 0 at v = 0) is glTexImage2D/3D's, so the
// bytes go up as they are. Float32 tables as RGB32F (desktop GL filters float
// textures linearly; WebGL2 needs OES_texture_float_linear), float16 ones as
// RGB16F. LINEAR + CLAMP_TO_EDGE with texel-centre coordinates is the C++'s
// TableView::SampleBilinear / SampleTrilinear. No mipmaps.
GLuint UploadTable(const Bake& bake, const Json& entry) {
    const int w = entry["width"], h = entry["height"], d = entry["depth"], c = entry["channels"];
    const size_t offset = entry[bake.half ? "float16_offset" : "float32_offset"];
    const size_t bytes = entry["values"].get<size_t>() * (bake.half ? 2 : 4);
    if (offset + bytes > bake.blob.size()) throw Error("table beyond the end of the blob");
    const GLenum internal =
        c == 4 ? (bake.half ? GL_RGBA16F : GL_RGBA32F) : (bake.half ? GL_RGB16F : GL_RGB32F);
    const GLenum format = c == 4 ? GL_RGBA : GL_RGB;
    const GLenum type = bake.half ? GL_HALF_FLOAT : GL_FLOAT;
    const GLenum target = d > 1 ? GL_TEXTURE_3D : GL_TEXTURE_2D;
    GLuint texture = 0;
    glGenTextures(1, &texture);
    glBindTexture(target, texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);  // RGB rows need not be 4-byte aligned
    const void* data = bake.blob.data() + offset;
    if (d > 1) {
        glTexImage3D(target, 0, internal, w, h, d, 0, format, type, data);
    } else {
        glTexImage2D(target, 0, internal, w, h, 0, format, type, data);
    }
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    CheckGl("UploadTable");
    return texture;
}

// An empty float render target (hillaire's frame tables), sampled like the tables.
GLuint MakeTarget(GLenum target, int w, int h, int d) {
    GLuint texture = 0;
    glGenTextures(1, &texture);
    glBindTexture(target, texture);
    if (target == GL_TEXTURE_3D) {
        glTexImage3D(target, 0, GL_RGBA32F, w, h, d, 0, GL_RGBA, GL_FLOAT, nullptr);
    } else {
        glTexImage2D(target, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, nullptr);
    }
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    CheckGl("MakeTarget");
    return texture;
}

// Which sampler reads which baked table: the sampler names of shaders/*.glsl
// (docs/engine.md lists them per model) and the table names of "raw".
const struct {
    const char* sampler;
    const char* table;
} kBakedSamplers[] = {
    {"atmos_transmittance_texture", "transmittance"},
    {"atmos_irradiance_texture", "irradiance"},
    {"atmos_scattering_texture", "scattering"},
    {"atmos_single_mie_texture", "single_mie_scattering"},
    {"atmos_multiple_scattering_texture", "multiple_scattering"},
};

// ---- 4. programs ----

// A full-screen triangle from gl_VertexID alone (no vertex buffer; core
// profile still needs a vertex array object bound).
constexpr const char* kVertexShader = R"(#version 330 core
void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}
)";

// The sky pass: what `atmos render` computes per pixel (ShadePixel,
// src/atmos/render/render.h): the ray of Camera::RayDirection through the pixel
// centre, (sky + ground) x irradiance, optionally the sun's (uniform) disc.
// gl_FragCoord is the pixel centre with y up: row y of the image (top down)
// is gl_FragCoord.y = height - y - 0.5, which gives the C++'s
// v = (1 - 2 (y + 0.5) / height) tan(fov_y / 2).
constexpr const char* kSkyMain = R"(
uniform vec3 u_camera;      // metres from the planet's centre
uniform vec3 u_forward, u_right, u_up;
uniform float u_tan_half_fov_y;
uniform vec2 u_size;        // framebuffer width, height
uniform vec3 u_sun;         // unit, toward the sun
uniform float u_sun_irradiance;
uniform bool u_sun_disc;
layout(location = 0) out vec4 frag_radiance;
void main() {
    vec2 p = gl_FragCoord.xy;
    float u = (2.0 * p.x / u_size.x - 1.0) * u_tan_half_fov_y * (u_size.x / u_size.y);
    float v = (2.0 * p.y / u_size.y - 1.0) * u_tan_half_fov_y;
    vec3 dir = normalize(u_forward + u_right * u + u_up * v);
    vec3 sky, ground, transmittance;
    bool hits_ground;
    atmos_Evaluate(u_camera, dir, u_sun, sky, ground, transmittance, hits_ground);
    vec3 irradiance = ATMOS_SOLAR_IRRADIANCE * u_sun_irradiance;
    vec3 radiance = (sky + ground) * irradiance;
    if (u_sun_disc && !hits_ground && dot(dir, u_sun) >= cos(ATMOS_SUN_ANGULAR_RADIUS)) {
        radiance += irradiance * transmittance /
                    (ATMOS_PI * ATMOS_SUN_ANGULAR_RADIUS * ATMOS_SUN_ANGULAR_RADIUS);
    }
    frag_radiance = vec4(max(radiance, vec3(0.0)), 1.0);
}
)";

// Hillaire's pass 1: one texel of the sky-view table per fragment.
constexpr const char* kSkyViewMain = R"(
uniform float u_r;    // camera radius, at least 1 m above the ground
uniform vec3 u_sun;   // the sun in the x-z plane at the camera's mu_s
layout(location = 0) out vec4 frag_sky_view;
void main() {
    frag_sky_view = vec4(atmos_SkyViewTexel(ivec2(gl_FragCoord.xy), u_r, u_sun), 1.0);
}
)";

// Hillaire's pass 2, one per slice k: each froxel (x, y, k) continues slice
// k - 1's in-scatter L and transmittance T (read from a 32 x 32 copy) and
// writes layer k of both volumes and the copy for slice k + 1 (ping-pong).
constexpr const char* kAerialPerspectiveMain = R"(
uniform int u_slice;
uniform vec3 u_camera;
uniform vec3 u_sun;
uniform sampler2D u_prev_scatter;
uniform sampler2D u_prev_transmittance;
layout(location = 0) out vec4 frag_scatter;
layout(location = 1) out vec4 frag_transmittance;
layout(location = 2) out vec4 next_scatter;
layout(location = 3) out vec4 next_transmittance;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 L = vec3(0.0), T = vec3(1.0);
    if (u_slice > 0) {
        L = texelFetch(u_prev_scatter, p, 0).rgb;
        T = texelFetch(u_prev_transmittance, p, 0).rgb;
    }
    atmos_AerialPerspectiveStep(ivec3(p, u_slice), u_camera, u_sun, L, T);
    frag_scatter = vec4(L, 1.0);
    frag_transmittance = vec4(T, 1.0);
    next_scatter = frag_scatter;
    next_transmittance = frag_transmittance;
}
)";

GLuint Compile(GLenum type, const std::string& source) {
    const GLuint shader = glCreateShader(type);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        throw Error(std::string("shader compile error: ") + log);
    }
    return shader;
}

// "#version 330 core" + the bake's GLSL (constants, common.glsl, NAME.glsl) + a main.
GLuint Link(const std::string& model_glsl, const char* main_source) {
    const GLuint program = glCreateProgram();
    glAttachShader(program, Compile(GL_VERTEX_SHADER, kVertexShader));
    glAttachShader(program, Compile(GL_FRAGMENT_SHADER,
                                    "#version 330 core\n" + model_glsl + "\n" + main_source));
    glLinkProgram(program);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetProgramInfoLog(program, sizeof log, nullptr, log);
        throw Error(std::string("link error: ") + log);
    }
    return program;
}

GLint Uniform(GLuint program, const char* name) { return glGetUniformLocation(program, name); }
void SetVec3(GLuint program, const char* name, Vec3 v) {
    glUniform3f(Uniform(program, name), static_cast<float>(v.x), static_cast<float>(v.y),
                static_cast<float>(v.z));
}

// ---- the renderer: tables, programs, frame tables ----

struct Bound {
    std::string sampler;
    GLenum target;
    GLuint texture;
};

struct Renderer {
    GLuint sky = 0;              // the sky pass
    std::vector<Bound> units;    // texture unit i of the sky pass
    double bottom = 0, top = 0;  // the atmosphere's radii
    bool frame_tables = false;   // hillaire: sky-view and aerial-perspective passes
    GLuint sky_view_pass = 0, ap_pass = 0;
    GLuint sky_view = 0, ap_scatter = 0, ap_transmittance = 0;
    GLuint ap_copy[2][2] = {};  // [ping-pong][L, T], 32 x 32
    GLuint sky_view_fb = 0, ap_fb = 0;
    GLuint baked_units[2] = {};  // hillaire's two baked tables for its passes
};

// hillaire.glsl's frame tables: ATMOS_SKY_VIEW_WIDTH x ATMOS_SKY_VIEW_HEIGHT and
// ATMOS_AP_SIZE^3 (constants of the model's file, not of the bake).
constexpr int kSkyViewWidth = 192, kSkyViewHeight = 108, kApSize = 32;

// Every active sampler of `program` must be one of `names` (given a texture
// unit): an unbound sampler would silently read unit 0.
void RequireSamplers(GLuint program, const std::vector<std::string>& names) {
    GLint count = 0;
    glGetProgramiv(program, GL_ACTIVE_UNIFORMS, &count);
    for (GLint i = 0; i < count; ++i) {
        char name[256];
        GLint size = 0;
        GLenum type = 0;
        glGetActiveUniform(program, static_cast<GLuint>(i), sizeof name, nullptr, &size, &type,
                           name);
        const bool is_sampler = type == GL_SAMPLER_2D || type == GL_SAMPLER_3D;
        if (is_sampler && std::find(names.begin(), names.end(), name) == names.end()) {
            throw Error(std::string("no table for the shader's sampler ") + name);
        }
    }
}

// Texture units of a program: every baked table whose sampler the program
// declares; then the frame tables. A sampler left without a table is an error
// (a model this host does not know: add it to kBakedSamplers).
void BindBakedTables(Renderer* r, const Bake& bake, GLuint program) {
    glUseProgram(program);
    const Json& tables = bake.json["raw"]["tables"];
    for (const auto& s : kBakedSamplers) {
        const GLint location = Uniform(program, s.sampler);
        if (location < 0) continue;  // not declared (or not used) by this model
        if (!tables.contains(s.table)) {
            throw Error(std::string("the shader reads ") + s.sampler + " but the bake has no '" +
                        s.table + "' table");
        }
        const Json& entry = tables[s.table];
        glUniform1i(location, static_cast<GLint>(r->units.size()));
        const GLenum target = entry["depth"].get<int>() > 1 ? GL_TEXTURE_3D : GL_TEXTURE_2D;
        r->units.push_back({s.sampler, target, UploadTable(bake, entry)});
    }
    r->frame_tables = Uniform(program, "atmos_sky_view_texture") >= 0;
    if (r->frame_tables) {
        r->sky_view = MakeTarget(GL_TEXTURE_2D, kSkyViewWidth, kSkyViewHeight, 1);
        r->ap_scatter = MakeTarget(GL_TEXTURE_3D, kApSize, kApSize, kApSize);
        r->ap_transmittance = MakeTarget(GL_TEXTURE_3D, kApSize, kApSize, kApSize);
        const struct {
            const char* sampler;
            GLenum target;
            GLuint texture;
        } frame[] = {{"atmos_sky_view_texture", GL_TEXTURE_2D, r->sky_view},
                     {"atmos_ap_scatter_texture", GL_TEXTURE_3D, r->ap_scatter},
                     {"atmos_ap_transmittance_texture", GL_TEXTURE_3D, r->ap_transmittance}};
        for (const auto& f : frame) {
            glUniform1i(Uniform(program, f.sampler), static_cast<GLint>(r->units.size()));
            r->units.push_back({f.sampler, f.target, f.texture});
        }
    }
    std::vector<std::string> names;
    for (const Bound& b : r->units) names.push_back(b.sampler);
    RequireSamplers(program, names);
    CheckGl("BindBakedTables");
}

// Hillaire's passes: programs, the ping-pong copies and the framebuffers.
void MakeFramePasses(Renderer* r, const Bake& bake) {
    r->sky_view_pass = Link(bake.glsl, kSkyViewMain);
    r->ap_pass = Link(bake.glsl, kAerialPerspectiveMain);
    // The passes read the two baked tables on units 0 and 1, the previous
    // slice's copies on 2 and 3.
    for (GLuint pass : {r->sky_view_pass, r->ap_pass}) {
        glUseProgram(pass);
        glUniform1i(Uniform(pass, "atmos_transmittance_texture"), 0);
        glUniform1i(Uniform(pass, "atmos_multiple_scattering_texture"), 1);
    }
    glUniform1i(Uniform(r->ap_pass, "u_prev_scatter"), 2);
    glUniform1i(Uniform(r->ap_pass, "u_prev_transmittance"), 3);
    RequireSamplers(r->sky_view_pass,
                    {"atmos_transmittance_texture", "atmos_multiple_scattering_texture"});
    RequireSamplers(r->ap_pass, {"atmos_transmittance_texture", "atmos_multiple_scattering_texture",
                                 "u_prev_scatter", "u_prev_transmittance"});
    for (const Bound& b : r->units) {
        if (b.sampler == "atmos_transmittance_texture") r->baked_units[0] = b.texture;
        if (b.sampler == "atmos_multiple_scattering_texture") r->baked_units[1] = b.texture;
    }
    for (auto& copy : r->ap_copy) {
        for (GLuint& t : copy) t = MakeTarget(GL_TEXTURE_2D, kApSize, kApSize, 1);
    }
    glGenFramebuffers(1, &r->sky_view_fb);
    glBindFramebuffer(GL_FRAMEBUFFER, r->sky_view_fb);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->sky_view, 0);
    glGenFramebuffers(1, &r->ap_fb);
    CheckGl("MakeFramePasses");
}

// The frame's camera of Hillaire's aerial-perspective volume (atmos_ap_*).
void SetApCamera(GLuint program, const Camera& c, double aspect) {
    SetVec3(program, "atmos_ap_forward", c.forward);
    SetVec3(program, "atmos_ap_right", c.right);
    SetVec3(program, "atmos_ap_up", c.up);
    glUniform1f(Uniform(program, "atmos_ap_tan_half_fov_y"), static_cast<float>(c.tan_half_fov_y));
    glUniform1f(Uniform(program, "atmos_ap_aspect"), static_cast<float>(aspect));
}

// ---- 5. a frame ----

// HillaireModel::BuildFrame: for a camera inside the atmosphere, the sky-view
// table for its radius and sun, and the aerial-perspective volume for its
// frustum. Outside the atmosphere atmos_Evaluate marches and reads neither.
void BuildFrameTables(const Renderer& r, const View& view, double aspect) {
    const Vec3 pos = view.camera.position;
    const double radius = std::sqrt(Dot(pos, pos));
    if (!(radius <= r.top)) return;
    const double mu_s = std::clamp(Dot(view.sun, pos) / radius, -1.0, 1.0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.baked_units[0]);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, r.baked_units[1]);
    // Pass 1: sky-view.
    glUseProgram(r.sky_view_pass);
    glUniform1f(Uniform(r.sky_view_pass, "u_r"),
                static_cast<float>(std::max(radius, r.bottom + 1.0)));
    SetVec3(r.sky_view_pass, "u_sun", {std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s});
    glBindFramebuffer(GL_FRAMEBUFFER, r.sky_view_fb);
    glViewport(0, 0, kSkyViewWidth, kSkyViewHeight);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    // Pass 2: aerial perspective, slice by slice.
    glUseProgram(r.ap_pass);
    SetApCamera(r.ap_pass, view.camera, aspect);
    SetVec3(r.ap_pass, "u_camera", pos);
    SetVec3(r.ap_pass, "u_sun", view.sun);
    glBindFramebuffer(GL_FRAMEBUFFER, r.ap_fb);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                              GL_COLOR_ATTACHMENT3};
    glDrawBuffers(4, buffers);
    glViewport(0, 0, kApSize, kApSize);
    for (int k = 0; k < kApSize; ++k) {
        const GLuint* prev = r.ap_copy[(k + 1) % 2];
        const GLuint* next = r.ap_copy[k % 2];
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, r.ap_scatter, 0, k);
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, r.ap_transmittance, 0, k);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT2, GL_TEXTURE_2D, next[0], 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT3, GL_TEXTURE_2D, next[1], 0);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, prev[0]);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, prev[1]);
        glUniform1i(Uniform(r.ap_pass, "u_slice"), k);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    CheckGl("BuildFrameTables");
}

// The sky pass into `target` (a width x height RGBA32F framebuffer), after
// BuildFrameTables for a model with frame tables.
void DrawSky(const Renderer& r, const View& view, int width, int height, bool sun_disc,
             GLuint target) {
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    glViewport(0, 0, width, height);
    glUseProgram(r.sky);
    for (size_t i = 0; i < r.units.size(); ++i) {
        glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(i));
        glBindTexture(r.units[i].target, r.units[i].texture);
    }
    const double aspect = static_cast<double>(width) / height;
    if (r.frame_tables) SetApCamera(r.sky, view.camera, aspect);
    const Camera& c = view.camera;
    SetVec3(r.sky, "u_camera", c.position);
    SetVec3(r.sky, "u_forward", c.forward);
    SetVec3(r.sky, "u_right", c.right);
    SetVec3(r.sky, "u_up", c.up);
    glUniform1f(Uniform(r.sky, "u_tan_half_fov_y"), static_cast<float>(c.tan_half_fov_y));
    glUniform2f(Uniform(r.sky, "u_size"), static_cast<float>(width), static_cast<float>(height));
    SetVec3(r.sky, "u_sun", view.sun);
    glUniform1f(Uniform(r.sky, "u_sun_irradiance"), static_cast<float>(view.sun_irradiance));
    glUniform1i(Uniform(r.sky, "u_sun_disc"), sun_disc ? 1 : 0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    CheckGl("DrawSky");
}

// ---- 6. output ----

// PFM (Portable Float Map): "PF", width height, -1.0 (little-endian), then
// RGB float32 rows from the bottom up: glReadPixels' order.
void WritePfm(const std::string& path, int width, int height, const std::vector<float>& rgba) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw Error("cannot write '" + path + "'");
    out << "PF\n" << width << " " << height << "\n-1.0\n";
    std::vector<float> rgb(static_cast<size_t>(width) * height * 3);
    for (size_t i = 0; i < rgb.size() / 3; ++i) {
        for (int ch = 0; ch < 3; ++ch) rgb[3 * i + ch] = rgba[4 * i + ch];
    }
    out.write(reinterpret_cast<const char*>(rgb.data()),
              static_cast<std::streamsize>(rgb.size() * sizeof(float)));
    if (!out) throw Error("cannot write '" + path + "'");
}

// ---- 7. tables computed on the GPU (docs/engine.md, "Tables computed on the GPU") ----

// A render target of "gpu_precompute"."targets": an RGBA32F 2D or 3D texture.
struct PassTarget {
    GLenum target = GL_TEXTURE_2D;
    GLuint texture = 0;
    int width = 1, height = 1, depth = 1;
};

// Runs the bake's "gpu_precompute" pass list as it is (io/gpu_passes.h): per
// pass its program ("#version 330 core", "#define ENTRY 1", the listed GLSL
// files), its inputs on texture units, one full-screen triangle per layer of
// its target (atmos_layer), blending ONE, ONE for "add". Each pass is timed by
// the wall clock between glFinish calls (`repeat` runs: medians). Then every
// table of "raw" is read back from the target of its name into a float32 blob
// laid out as the bake's tables.f32 (same offsets), written to `output`.
void RunPrecompute(const std::string& dir, const Bake& bake, const std::string& output,
                   int repeat) {
    if (!bake.json.contains("gpu_precompute")) {
        throw Error("the bake in '" + dir +
                    "' has no \"gpu_precompute\" (its model's tables are not computed on the GPU)");
    }
    const Json& pc = bake.json["gpu_precompute"];
    std::string glsl;
    for (const Json& file : pc["shaders"])
        glsl += ReadFile(dir + "/" + file.get<std::string>()) + "\n";
    CreateContext();
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    std::map<std::string, PassTarget> targets;
    for (const auto& [name, t] : pc["targets"].items()) {
        PassTarget p;
        p.width = t["width"];
        p.height = t["height"];
        p.depth = t["depth"];
        if (t["channels"].get<int>() != 4) throw Error("target '" + name + "' is not RGBA");
        p.target = p.depth > 1 ? GL_TEXTURE_3D : GL_TEXTURE_2D;
        p.texture = MakeTarget(p.target, p.width, p.height, p.depth);
        targets[name] = p;
    }
    std::map<std::string, GLuint> programs;  // by entry
    const Json& passes = pc["passes"];
    for (const Json& pass : passes) {
        const std::string entry = pass["entry"];
        if (!programs.count(entry)) programs[entry] = Link("#define " + entry + " 1\n" + glsl, "");
    }
    GLuint fb = 0;
    glGenFramebuffers(1, &fb);
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(GL_FUNC_ADD);
    using Clock = std::chrono::steady_clock;
    std::vector<std::vector<double>> pass_ms(passes.size());
    std::vector<double> total_ms;
    for (int run = 0; run < repeat; ++run) {
        glFinish();
        const Clock::time_point start = Clock::now();
        for (size_t i = 0; i < passes.size(); ++i) {
            const Json& pass = passes[i];
            const Clock::time_point t0 = Clock::now();
            const GLuint program = programs[pass["entry"].get<std::string>()];
            const std::string target_name = pass["target"];
            if (!targets.count(target_name))
                throw Error("pass target '" + target_name + "' unknown");
            const PassTarget& out = targets[target_name];
            glUseProgram(program);
            std::vector<std::string> samplers;
            GLint unit = 0;
            for (const auto& [sampler, input] : pass["inputs"].items()) {
                const std::string in = input.get<std::string>();
                if (!targets.count(in) || in == target_name) {
                    throw Error("pass '" + pass["name"].get<std::string>() + "' reads '" + in +
                                "'");
                }
                glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
                glBindTexture(targets[in].target, targets[in].texture);
                glUniform1i(Uniform(program, sampler.c_str()), unit++);
                samplers.push_back(sampler);
            }
            if (run == 0) RequireSamplers(program, samplers);
            for (const auto& [name, value] : pass["uniforms"].items()) {
                glUniform1i(Uniform(program, name.c_str()), value.get<int>());
            }
            if (pass["blend"] == "add") {
                glEnable(GL_BLEND);
            } else {
                glDisable(GL_BLEND);
            }
            glViewport(0, 0, out.width, out.height);
            const GLint layer = Uniform(program, "atmos_layer");
            for (int z = 0; z < out.depth; ++z) {
                if (out.target == GL_TEXTURE_3D) {
                    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, out.texture, 0,
                                              z);
                } else {
                    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                                           out.texture, 0);
                }
                if (z == 0 && glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
                    throw Error("RGBA32F target '" + target_name + "' incomplete");
                }
                glUniform1i(layer, z);
                glDrawArrays(GL_TRIANGLES, 0, 3);
            }
            glFinish();
            pass_ms[i].push_back(
                std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
            CheckGl(pass["name"].get<std::string>().c_str());
        }
        total_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    }
    glDisable(GL_BLEND);
    // The tables, laid out as "raw" (channel fastest, then x, y, layer).
    const Json& raw = bake.json["raw"];
    std::vector<float> blob(raw["float32"]["bytes"].get<size_t>() / 4, 0.0f);
    for (const auto& [name, entry] : raw["tables"].items()) {
        if (!targets.count(name)) throw Error("the passes compute no table '" + name + "'");
        const PassTarget& t = targets[name];
        const int c = entry["channels"];
        const size_t texels = static_cast<size_t>(t.width) * t.height * t.depth;
        if (entry["width"] != t.width || entry["height"] != t.height || entry["depth"] != t.depth ||
            entry["float32_offset"].get<size_t>() / 4 + texels * c > blob.size()) {
            throw Error("target '" + name + "' does not match its table in \"raw\"");
        }
        std::vector<float> rgba(texels * 4);
        glBindTexture(t.target, t.texture);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glGetTexImage(t.target, 0, GL_RGBA, GL_FLOAT, rgba.data());
        float* dst = blob.data() + entry["float32_offset"].get<size_t>() / 4;
        for (size_t i = 0; i < texels; ++i) {
            for (int ch = 0; ch < c; ++ch) dst[i * c + ch] = rgba[i * 4 + ch];
        }
    }
    CheckGl("readback");
    std::ofstream file(output, std::ios::binary);
    file.write(reinterpret_cast<const char*>(blob.data()),
               static_cast<std::streamsize>(blob.size() * sizeof(float)));
    if (!file) throw Error("cannot write '" + output + "'");
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    const std::string renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    std::printf(
        "%s precompute on %s%s: %zu passes, %.1f ms (medians of %d runs, glFinish-bracketed "
        "wall clock per pass)\n",
        bake.json["model"].get<std::string>().c_str(), renderer.c_str(),
        renderer.find("llvmpipe") != std::string::npos ? " (CPU-emulated: Mesa llvmpipe)" : "",
        passes.size(), median(total_ms), repeat);
    for (size_t i = 0; i < passes.size(); ++i) {
        const Json& pass = passes[i];
        std::printf("  %-44s %-20s %10.2f ms\n", pass["name"].get<std::string>().c_str(),
                    pass["target"].get<std::string>().c_str(), median(pass_ms[i]));
    }
}

constexpr const char* kUsage =
    "usage: atmos_gl_host BAKE_DIR (--view NAME | --camera K=V,... --sun K=V,...) -o OUT.pfm\n"
    "                     [--size WxH] [--format f32|f16] [--sun-disc] [--repeat N] [--info]\n"
    "       atmos_gl_host BAKE_DIR --precompute OUT.f32 [--repeat N]\n"
    "Renders one view of a bake (`atmos bake --model NAME -o BAKE_DIR`) with OpenGL 3.3 core\n"
    "(EGL, headless) into an RGBA32F framebuffer and writes the linear radiance as PFM, as\n"
    "`atmos render --load BAKE_DIR` of the same view.\n"
    "  --view NAME     one of the 12 standard views (docs/views.md)\n"
    "  --camera SPEC   altitude=M,azimuth=DEG,elevation=DEG,roll=DEG,fov=DEG (as atmos render)\n"
    "  --sun SPEC      elevation=DEG[,azimuth=DEG] (with --camera)\n"
    "  --size WxH      framebuffer size (default 320x180)\n"
    "  --format f32|f16  which blob to upload (default f32)\n"
    "  --sun-disc      add the sun's uniform disc\n"
    "  --repeat N      draw the frame (or run the passes) N times and print median times\n"
    "  --precompute OUT.f32  run the bake's \"gpu_precompute\" passes, write the tables they\n"
    "                  compute as a float32 blob laid out as the bake's tables.f32 and print\n"
    "                  each pass's time\n"
    "  --info          print the GL renderer and exit\n"
    "Exit status: 0 ok, 2 bad input or GL error, 3 no OpenGL 3.3 context (EGL).\n";

int Run(int argc, char** argv) {
    std::string dir, view_name, camera, sun, output, format = "f32", precompute;
    int width = 320, height = 180, repeat = 1;
    bool sun_disc = false, info = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw Error(a + " needs a value");
            return argv[++i];
        };
        if (a == "--help" || a == "-h") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (a == "--view") {
            view_name = value();
        } else if (a == "--camera") {
            camera = value();
        } else if (a == "--sun") {
            sun = value();
        } else if (a == "-o" || a == "--output") {
            output = value();
        } else if (a == "--format") {
            format = value();
        } else if (a == "--size") {
            const std::string s = value();
            if (std::sscanf(s.c_str(), "%dx%d", &width, &height) != 2 || width < 1 || height < 1 ||
                width > 16384 || height > 16384) {
                throw Error("--size must be WxH with 1 <= W, H <= 16384, got '" + s + "'");
            }
        } else if (a == "--repeat") {
            repeat = std::atoi(value().c_str());
            if (repeat < 1 || repeat > 10000) throw Error("--repeat must be in [1, 10000]");
        } else if (a == "--precompute") {
            precompute = value();
        } else if (a == "--sun-disc") {
            sun_disc = true;
        } else if (a == "--info") {
            info = true;
        } else if (!a.empty() && a[0] != '-' && dir.empty()) {
            dir = a;
        } else {
            throw Error("unknown argument '" + a + "' (--help)");
        }
    }
    if (info) {
        CreateContext();
        std::printf("%s | %s | GLSL %s\n", glGetString(GL_RENDERER), glGetString(GL_VERSION),
                    glGetString(GL_SHADING_LANGUAGE_VERSION));
        return 0;
    }
    if (!precompute.empty()) {
        if (dir.empty()) throw Error("--precompute needs BAKE_DIR (--help)");
        if (!view_name.empty() || !camera.empty() || !output.empty()) {
            throw Error("--precompute writes tables: no --view, --camera or -o");
        }
        RunPrecompute(dir, LoadBake(dir, false), precompute, repeat);
        return 0;
    }
    if (dir.empty() || output.empty()) throw Error("need BAKE_DIR and -o OUT.pfm (--help)");
    if (format != "f32" && format != "f16") throw Error("--format must be f32 or f16");
    if (view_name.empty() == camera.empty()) throw Error("give --view NAME or --camera SPEC");
    if (!camera.empty() && sun.empty()) throw Error("--camera needs --sun elevation=DEG");

    const Bake bake = LoadBake(dir, format == "f16");
    const std::string model = bake.json["model"];
    Renderer r;
    r.bottom = bake.json["atmosphere"]["bottom_radius"];
    r.top = bake.json["atmosphere"]["top_radius"];
    View view;
    if (!view_name.empty()) {
        if (!StandardView(view_name, r.bottom, r.top, &view)) {
            throw Error("unknown view '" + view_name + "' (docs/views.md)");
        }
    } else {
        view = FreeView(camera, sun, r.bottom);
    }

    CreateContext();
    GLuint vao = 0;  // core profile: a bound vertex array, even without attributes
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    r.sky = Link(bake.glsl, kSkyMain);
    BindBakedTables(&r, bake, r.sky);
    if (r.frame_tables) MakeFramePasses(&r, bake);

    // The float framebuffer: RGBA32F (colour-renderable in core GL 3.0+).
    GLuint fb = 0, rb = 0;
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, width, height);
    glGenFramebuffers(1, &fb);
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        throw Error("RGBA32F framebuffer incomplete");
    }

    // Frames, timed by the wall clock between glFinish calls: the frame
    // tables' passes, then the sky pass (on llvmpipe the "GPU" is the CPU, and
    // its GL_TIME_ELAPSED queries miss the deferred rasterisation: use them on
    // a real GPU, where they avoid the glFinish stalls).
    using Clock = std::chrono::steady_clock;
    auto ms_since = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    std::vector<double> frame_ms, tables_ms, sky_ms;
    const double aspect = static_cast<double>(width) / height;
    for (int i = 0; i < repeat; ++i) {
        glFinish();
        const Clock::time_point t0 = Clock::now();
        if (r.frame_tables) BuildFrameTables(r, view, aspect);
        glFinish();
        tables_ms.push_back(ms_since(t0));
        const Clock::time_point t1 = Clock::now();
        DrawSky(r, view, width, height, sun_disc, fb);
        glFinish();
        sky_ms.push_back(ms_since(t1));
        frame_ms.push_back(ms_since(t0));
    }
    CheckGl("frames");
    std::vector<float> rgba(static_cast<size_t>(width) * height * 4);
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
    CheckGl("glReadPixels");
    WritePfm(output, width, height, rgba);
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    std::printf(
        "%s %dx%d on %s: frame %.2f ms = frame tables %.2f ms + sky pass %.2f ms (medians of %d, "
        "glFinish-bracketed wall clock; the first frame %.2f ms)\n",
        model.c_str(), width, height, glGetString(GL_RENDERER), median(frame_ms), median(tables_ms),
        median(sky_ms), repeat, frame_ms.front());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return Run(argc, argv);
    } catch (const NoContext& e) {
        std::fprintf(stderr, "atmos_gl_host: no OpenGL 3.3 context: %s\n", e.what());
        return kExitNoContext;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atmos_gl_host: error: %s\n", e.what());
        return 2;
    }
}
