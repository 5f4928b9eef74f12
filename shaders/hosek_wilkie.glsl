// atmos shaders: the `hosek-wilkie` model (Hosek & Wilkie 2012, "An Analytic
// Model for Full Spectral Sky-Dome Radiance", ACM TOG 31(4), eq. 8-9) from the
// constants of `atmos bake --model hosek-wilkie` (GLSL ES 3.00 and GLSL 3.30
// core: no extensions). It needs no tables.
//
// Written for atmos from the paper's equations and our C++
// (src/atmos/models/hosek_wilkie.h: HosekWilkieEvaluator, HosekWilkieCook,
// HosekWilkieRadiance); every function names the C++ function it mirrors.
//
// Use: include, in this order,
//   1. the #version line and `precision highp float;` (GLSL ES),
//   2. DIR/shaders/hosek_wilkie_constants.glsl (written by the bake: the
//      atmosphere's radii, ATMOS_HW_SOURCES, ATMOS_HW_CONTROL: per source the six
//      Bezier control points of A B C D E F G I H and L_M, already blended in
//      turbidity and ground albedo; ATMOS_HW_MIX: each output channel's weights
//      of the sources, with the division by the solar irradiance),
//   3. DIR/shaders/common.glsl (the shared math and geometry),
//   4. this file.
// The sun may move freely: the shader evaluates the Bezier curves at the sun's
// elevation per pixel (6 x 10 multiply-adds per source).
//
// Units: results per unit solar irradiance (multiply by ATMOS_SOLAR_IRRADIANCE,
// the atmosphere's, times the scene's), as every atmos model. Valid (as the
// C++): a viewer on the ground (a camera above it is treated as on the ground),
// the sun 0-90 degrees above the horizon (below it, it is raised to the
// horizon); rays that hit the ground are black with T = 0; no transmittance
// (1 for sky rays).

// HosekWilkieCook: parameter p (0-9) of source `source` at the Bezier
// coordinate with weights b (the quintic Bernstein basis).
float atmos_HosekWilkieParameter(int source, int p, float b[6]) {
    float s = 0.0;
    for (int i = 0; i < 6; ++i) s += b[i] * ATMOS_HW_CONTROL[60 * source + 10 * i + p];
    return s;
}

// HosekWilkieRadiance (eq. 8-9): F(theta, gamma) L_M of one source, with
// chi(H, gamma) = (1 + cos^2 gamma) / (1 + H^2 - 2 H cos gamma)^(3/2); the
// data's parameter order is A B C D E F G I H, L_M last.
float atmos_HosekWilkieRadiance(int source, float b[6], float cos_theta, float gamma) {
    float k[10];
    for (int p = 0; p < 10; ++p) k[p] = atmos_HosekWilkieParameter(source, p, b);
    float cos_gamma = cos(gamma);
    float h = k[8];
    float q = 1.0 + h * h - 2.0 * h * cos_gamma;
    float chi = (1.0 + cos_gamma * cos_gamma) / (q * sqrt(q));
    float f = (1.0 + k[0] * exp(k[1] / (cos_theta + 0.01))) *
              (k[2] + k[3] * exp(k[4] * gamma) + k[5] * cos_gamma * cos_gamma + k[6] * chi +
               k[7] * sqrt(cos_theta));
    return f * k[9];
}

// HosekWilkieEvaluator::Evaluate (and SunTerms): the sky of one view ray.
void atmos_Evaluate(vec3 camera, vec3 dir, vec3 sun, out vec3 sky, out vec3 ground,
                    out vec3 transmittance, out bool hits_ground) {
    float t_start, t_end;
    bool inside =
        atmos_BeginRay(camera, dir, sky, ground, transmittance, hits_ground, t_start, t_end);
    if (hits_ground) transmittance = vec3(0.0);
    if (!inside || hits_ground) return;
    vec3 up = normalize(camera);
    // SunTerms: a sun below the horizon is raised to it.
    float cos_s = dot(sun, up);
    vec3 s = sun;
    if (cos_s < 0.0) {
        vec3 horizontal = sun - up * cos_s;
        float len = length(horizontal);
        s = len > 1e-9 ? horizontal / len : normalize(cross(up, vec3(1.0, 0.0, 0.0)));
        cos_s = 0.0;
    }
    // The C++'s pi/2 - acos(cos_s) as asin(cos_s): in float the difference
    // of two numbers near pi/2 is not 0 for a sun on the horizon, and the cube
    // root below turns 1e-7 into 0.005.
    float elevation = asin(clamp(cos_s, 0.0, 1.0));
    // HosekWilkieCook: x = (elevation / (pi / 2))^(1/3), the Bernstein weights
    // (pow(0, y) may be undefined in GLSL: the sun on the horizon is x = 0).
    float e = clamp(elevation / (0.5 * ATMOS_PI), 0.0, 1.0);
    float x = e > 0.0 ? pow(e, 1.0 / 3.0) : 0.0;
    float y = 1.0 - x;
    float b[6];
    b[0] = y * y * y * y * y;
    b[1] = 5.0 * y * y * y * y * x;
    b[2] = 10.0 * y * y * y * x * x;
    b[3] = 10.0 * y * y * x * x * x;
    b[4] = 5.0 * y * x * x * x * x;
    b[5] = x * x * x * x * x;
    float cos_theta = max(dot(dir, up), 0.0);
    float gamma = acos(clamp(dot(dir, s), -1.0, 1.0));
    vec3 c = vec3(0.0);
    for (int i = 0; i < ATMOS_HW_SOURCES; ++i) {
        float l = atmos_HosekWilkieRadiance(i, b, cos_theta, gamma);
        c += vec3(ATMOS_HW_MIX[i], ATMOS_HW_MIX[6 + i], ATMOS_HW_MIX[12 + i]) * l;
    }
    sky = max(c, vec3(0.0));
}
