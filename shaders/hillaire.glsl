// atmos shaders: the `hillaire` model (Hillaire 2020, "A Scalable and
// Production Ready Sky and Atmosphere Rendering Technique") over the tables of
// `atmos bake hillaire` (GLSL ES 3.00 and GLSL 3.30 core).
//
// Written for atmos from the paper's math and our C++ code; every function
// names the C++ function in src/atmos/models/hillaire.h (HillaireEvaluator,
// the mappings) or hillaire_stages.h (the per-frame passes) it mirrors, and
// the paper section it implements. It is not the paper's demo code.
//
// Use: the #version line and `precision highp float; precision highp
// sampler3D;` (ES), then DIR/shaders/hillaire_constants.glsl (written by the
// bake), DIR/shaders/common.glsl (the shared math and geometry), then this
// file. Baked tables (DIR/tables.f32 or .f16, "raw" in
// DIR/hillaire.json), LINEAR and CLAMP_TO_EDGE:
//   atmos_transmittance_texture        2D RGB 256 x 64   transmittance.exr
//   atmos_multiple_scattering_texture  2D RGB 32 x 32    multiple_scattering.exr
// Per frame, two passes render the paper's frame tables (RGBA32F or RGBA16F
// render targets), then the sky:
//   1. sky-view, 192 x 108: each texel atmos_SkyViewTexel (camera radius and
//      sun of the frame), into atmos_sky_view_texture;
//   2. aerial perspective, 32 x 32 x 32: for each slice k = 0..31, each texel
//      atmos_AerialPerspectiveStep from slice k - 1's L, T into layer k of
//      atmos_ap_scatter_texture and atmos_ap_transmittance_texture (and a
//      32 x 32 copy of L, T for slice k + 1: draw buffers), with the frame's
//      camera in the atmos_ap_* uniforms (atmos_AerialPerspectiveTexel does a
//      froxel in one go, without the copies);
//   3. per pixel atmos_Evaluate (what `atmos render` computes).
// A camera outside the atmosphere needs neither pass (atmos_Evaluate marches).
// Units: metres, planet-centred; results per unit solar irradiance.

uniform highp sampler2D atmos_transmittance_texture;
uniform highp sampler2D atmos_multiple_scattering_texture;
uniform highp sampler2D atmos_sky_view_texture;
uniform highp sampler3D atmos_ap_scatter_texture;
uniform highp sampler3D atmos_ap_transmittance_texture;
// The frame's camera (Camera: forward, right, up, tan of half the vertical
// field of view) and aspect ratio, for which the aerial-perspective volume is built.
uniform vec3 atmos_ap_forward;
uniform vec3 atmos_ap_right;
uniform vec3 atmos_ap_up;
uniform float atmos_ap_tan_half_fov_y;
uniform float atmos_ap_aspect;

const float ATMOS_SKY_VIEW_WIDTH = 192.0;
const float ATMOS_SKY_VIEW_HEIGHT = 108.0;
const int ATMOS_AP_SIZE = 32;
const int ATMOS_AP_BLEND_SLICE = 24;
const float ATMOS_SKY_VIEW_MIN_ALTITUDE = 1.0;

// ---- geometry (the shared helpers are in common.glsl) ----

// RayIntersectsGround (geometry.h; Bruneton's 2017 implementation notes).
bool atmos_RayIntersectsGround(float r, float mu) {
    return mu < 0.0 &&
           (ATMOS_BOTTOM_RADIUS - r) * (ATMOS_BOTTOM_RADIUS + r) + (r * mu) * (r * mu) >= 0.0;
}

// ---- baked tables (paper sections 5.1, 5.5.2) ----

// HillaireTransmittanceUv (Bruneton's 2017 implementation notes GetTransmittanceTextureUvFromRMu) and the
// lookup HillaireEvaluator::Transmittance: T(r, mu) to the top.
vec3 atmos_Transmittance(float r, float mu) {
    r = clamp(r, ATMOS_BOTTOM_RADIUS, ATMOS_TOP_RADIUS);
    float H = sqrt((ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS) * (ATMOS_TOP_RADIUS + ATMOS_BOTTOM_RADIUS));
    float rho = atmos_SafeSqrt((r - ATMOS_BOTTOM_RADIUS) * (r + ATMOS_BOTTOM_RADIUS));
    float d = atmos_DistanceToTop(r, atmos_ClampCosine(mu));
    float d_min = ATMOS_TOP_RADIUS - r;
    float d_max = rho + H;
    float x_mu = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
    vec2 uv = vec2(atmos_TextureCoord(clamp(x_mu, 0.0, 1.0), float(ATMOS_TRANSMITTANCE_WIDTH)),
                   atmos_TextureCoord(rho / H, float(ATMOS_TRANSMITTANCE_HEIGHT)));
    return texture(atmos_transmittance_texture, uv).rgb;
}
// HillaireEvaluator::TransmittanceToGround (Bruneton's 2017 implementation notes GetTransmittance, ray to the ground).
vec3 atmos_TransmittanceToGround(float r, float mu, float d) {
    float r_d = clamp(sqrt(d * d + 2.0 * r * mu * d + r * r), ATMOS_BOTTOM_RADIUS, ATMOS_TOP_RADIUS);
    float mu_d = atmos_ClampCosine((r * mu + d) / r_d);
    vec3 a = atmos_Transmittance(r_d, -mu_d);
    vec3 b = atmos_Transmittance(r, -mu);
    vec3 t;
    for (int c = 0; c < 3; ++c) t[c] = b[c] > 0.0 ? min(a[c] / b[c], 1.0) : 0.0;
    return t;
}
// HillaireEvaluator::SunTransmittance: T to the sun times the planet's shadow.
vec3 atmos_SunTransmittance(float r, float mu_s) {
    if (atmos_RayIntersectsGround(r, atmos_ClampCosine(mu_s))) return vec3(0.0);
    return atmos_Transmittance(r, mu_s);
}
// HillaireMsUv + HillaireEvaluator::MultipleScattering: Psi_ms (paper Eq. 10).
vec3 atmos_MultipleScattering(float r, float mu_s) {
    float x = clamp(0.5 * mu_s + 0.5, 0.0, 1.0);
    float y = clamp((r - ATMOS_BOTTOM_RADIUS) / (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS), 0.0, 1.0);
    vec2 uv = vec2(atmos_TextureCoord(x, 32.0), atmos_TextureCoord(y, 32.0));
    return texture(atmos_multiple_scattering_texture, uv).rgb;
}

// ---- the ray march (paper Eq. 1-3, 11; Hillaire 2015 energy-conserving step) ----

// HillaireEvaluator::Integrate: in-scattered radiance over [ta, tb] of
// origin + t dir in n segments, each sampled at ATMOS_SEGMENT_OFFSET of its
// length; adds to L, multiplies T. through_ground: points below the ground
// are taken at the ground (the aerial-perspective volume).
void atmos_Integrate(vec3 origin, vec3 dir, vec3 sun, float ta, float tb, int n, inout vec3 L,
                     inout vec3 T, bool through_ground) {
    if (!(tb > ta) || n < 1) return;
    float nu = dot(dir, sun);
    float phase_r = atmos_RayleighPhase(nu);
    float phase_m = atmos_MiePhase(nu);
    float dt = (tb - ta) / float(n);
    for (int i = 0; i < n; ++i) {
        vec3 p = origin + dir * (ta + (float(i) + ATMOS_SEGMENT_OFFSET) * dt);
        float r = length(p);
        if (through_ground && r < ATMOS_BOTTOM_RADIUS) {
            p = p * (ATMOS_BOTTOM_RADIUS / r);
            r = ATMOS_BOTTOM_RADIUS;
        }
        float mu_s = atmos_ClampCosine(dot(p, sun) / r);
        float alt = r - ATMOS_BOTTOM_RADIUS;
        vec3 d = atmos_Densities(alt);
        float d_r = d.x, d_m = d.y, d_a = d.z;
        vec3 sigma_r = ATMOS_RAYLEIGH_SCATTERING * d_r;
        vec3 sigma_m = ATMOS_MIE_SCATTERING * d_m;
        vec3 sigma_t = ATMOS_RAYLEIGH_SCATTERING * d_r + ATMOS_MIE_EXTINCTION * d_m +
                       ATMOS_ABSORPTION_EXTINCTION * d_a;
        vec3 S = atmos_SunTransmittance(r, mu_s) * (sigma_r * phase_r + sigma_m * phase_m) +
                 (sigma_r + sigma_m) * atmos_MultipleScattering(r, mu_s);
        vec3 step_t = exp(-sigma_t * dt);
        for (int c = 0; c < 3; ++c) {
            float s_int = sigma_t[c] > 0.0 ? (S[c] - S[c] * step_t[c]) / sigma_t[c] : S[c] * dt;
            L[c] += T[c] * s_int;
        }
        T *= step_t;
    }
}

// HillaireEvaluator::GroundReflection: Lambertian ground lit by the direct sun.
vec3 atmos_GroundReflection(vec3 g, vec3 sun) {
    vec3 n = normalize(g);
    float cos_sun = dot(n, sun);
    if (cos_sun <= 0.0) return vec3(0.0);
    return ATMOS_GROUND_ALBEDO * (cos_sun / ATMOS_PI) *
           atmos_Transmittance(ATMOS_BOTTOM_RADIUS, cos_sun);
}

// ---- sky-view table (paper section 5.3: non-linear latitude mapping) ----

// HillaireSkyViewHorizon: beta (horizon below the horizontal) and theta_h.
void atmos_SkyViewHorizon(float r, out float beta, out float theta_h) {
    float r_eff = max(r, ATMOS_BOTTOM_RADIUS + ATMOS_SKY_VIEW_MIN_ALTITUDE);
    float cos_beta = sqrt((r_eff - ATMOS_BOTTOM_RADIUS) * (r_eff + ATMOS_BOTTOM_RADIUS)) / r_eff;
    beta = acos(clamp(cos_beta, -1.0, 1.0));
    theta_h = ATMOS_PI - beta;
}
// HillaireSkyViewParams: unit coordinates -> (mu_v, cos_az).
void atmos_SkyViewParams(float r, float x, float y, out float mu_v, out float cos_az) {
    float beta, theta_h;
    atmos_SkyViewHorizon(r, beta, theta_h);
    float theta;
    if (y < 0.5) {
        float c = 1.0 - 2.0 * y;
        theta = theta_h * (1.0 - c * c);
    } else {
        float c = 2.0 * y - 1.0;
        theta = theta_h + beta * c * c;
    }
    mu_v = cos(theta);
    cos_az = atmos_ClampCosine(1.0 - 2.0 * x * x);
}
// HillaireSkyViewStage: texel (i, j) of the sky-view table for a camera at
// (0, 0, r) (r at least 1 m above the ground) and the sun `sun` in the x-z plane.
vec3 atmos_SkyViewTexel(ivec2 texel, float r, vec3 sun) {
    float mu_v, cos_az;
    atmos_SkyViewParams(r, float(texel.x) / (ATMOS_SKY_VIEW_WIDTH - 1.0),
                        float(texel.y) / (ATMOS_SKY_VIEW_HEIGHT - 1.0), mu_v, cos_az);
    float sin_v = atmos_SafeSqrt(1.0 - mu_v * mu_v);
    vec3 dir = vec3(sin_v * cos_az, sin_v * atmos_SafeSqrt(1.0 - cos_az * cos_az), mu_v);
    vec3 camera = vec3(0.0, 0.0, r);
    float t0, t1;
    bool ground;
    vec3 L = vec3(0.0), T = vec3(1.0);
    if (atmos_ClipToAtmosphere(camera, dir, t0, t1, ground)) {
        atmos_Integrate(camera, dir, sun, t0, t1, ATMOS_SKY_VIEW_STEPS, L, T, false);
    }
    return L;
}
// HillaireSkyViewUv + HillaireEvaluator::SkyView: the lookup, in the local frame.
vec3 atmos_SkyView(vec3 camera, vec3 dir, vec3 sun) {
    float r = length(camera);
    vec3 up = camera / r;
    float mu_v = atmos_ClampCosine(dot(dir, up));
    vec3 dir_h = dir - up * dot(dir, up);
    vec3 sun_h = sun - up * dot(sun, up);
    float lh = length(dir_h) * length(sun_h);
    float cos_az = lh > 1e-12 ? atmos_ClampCosine(dot(dir_h, sun_h) / lh) : 1.0;
    float beta, theta_h;
    atmos_SkyViewHorizon(r, beta, theta_h);
    float theta = acos(mu_v);
    float y;
    if (theta <= theta_h) {
        y = 0.5 * (1.0 - atmos_SafeSqrt(1.0 - clamp(theta / theta_h, 0.0, 1.0)));
    } else {
        y = 0.5 + 0.5 * sqrt(clamp((theta - theta_h) / beta, 0.0, 1.0));
    }
    float x = atmos_SafeSqrt(0.5 - 0.5 * cos_az);
    vec2 uv = vec2(atmos_TextureCoord(x, ATMOS_SKY_VIEW_WIDTH),
                   atmos_TextureCoord(y, ATMOS_SKY_VIEW_HEIGHT));
    return texture(atmos_sky_view_texture, uv).rgb;
}

// ---- aerial-perspective volume (paper section 5.4) ----

// HillaireApSliceDistance: slice centre k at ((k + 0.5) / 32)^2 32 D.
float atmos_ApSliceDistance(int k) {
    float w = (float(k) + 0.5) / float(ATMOS_AP_SIZE);
    return w * w * float(ATMOS_AP_SIZE) * ATMOS_AP_METRES_PER_SLICE;
}
// HillaireAerialPerspectiveStage, one slice of its cumulative march: for the
// frame's camera at `origin` (atmos_ap_* uniforms), continues L, T of froxel
// (i, j, slice - 1) (L = 0, T = 1 before slice 0) through the segment between
// the centres of slices slice - 1 and slice, ATMOS_AP_STEPS_PER_SLICE segments.
// One pass per slice, each reading the previous slice's L, T, marches every
// column once, as the C++ does.
void atmos_AerialPerspectiveStep(ivec3 froxel, vec3 origin, vec3 sun, inout vec3 L,
                                 inout vec3 T) {
    float u = (float(froxel.x) + 0.5) / float(ATMOS_AP_SIZE);
    float v = (float(froxel.y) + 0.5) / float(ATMOS_AP_SIZE);
    float tan_y = atmos_ap_tan_half_fov_y;
    vec3 dir = normalize(atmos_ap_forward + atmos_ap_right * ((2.0 * u - 1.0) * tan_y * atmos_ap_aspect) +
                         atmos_ap_up * ((1.0 - 2.0 * v) * tan_y));
    float t_in, t_out;
    if (!atmos_IntersectSphere(origin, dir, ATMOS_TOP_RADIUS, t_in, t_out) || t_out <= 0.0) return;
    t_in = max(t_in, 0.0);
    float t_prev = froxel.z > 0 ? atmos_ApSliceDistance(froxel.z - 1) : 0.0;
    float t_k = atmos_ApSliceDistance(froxel.z);
    atmos_Integrate(origin, dir, sun, clamp(t_prev, t_in, t_out), clamp(t_k, t_in, t_out),
                    ATMOS_AP_STEPS_PER_SLICE, L, T, true);
}
// HillaireAerialPerspectiveStage: froxel (i, j, slice) in one go, the steps of
// slices 0 to `slice` (for a renderer without the per-slice passes).
void atmos_AerialPerspectiveTexel(ivec3 froxel, vec3 origin, vec3 sun, out vec3 L, out vec3 T) {
    L = vec3(0.0);
    T = vec3(1.0);
    for (int k = 0; k <= froxel.z; ++k) {
        atmos_AerialPerspectiveStep(ivec3(froxel.xy, k), origin, sun, L, T);
    }
}
// HillaireEvaluator::AerialPerspective: the volume's lookup at distance d
// along dir; false outside the frustum or beyond the last slice centre.
bool atmos_AerialPerspective(vec3 dir, float d, out vec3 scatter, out vec3 trans) {
    scatter = vec3(0.0);
    trans = vec3(1.0);
    float a = dot(dir, atmos_ap_forward);
    if (a <= 0.0) return false;
    float tan_y = atmos_ap_tan_half_fov_y;
    float u = 0.5 * (dot(dir, atmos_ap_right) / (a * tan_y * atmos_ap_aspect) + 1.0);
    float v = 0.5 * (1.0 - dot(dir, atmos_ap_up) / (a * tan_y));
    float d_last = atmos_ApSliceDistance(ATMOS_AP_SIZE - 1);
    if (d > d_last) return false;
    float d_first = atmos_ApSliceDistance(0);
    float w = sqrt(max(d, d_first) / (float(ATMOS_AP_SIZE) * ATMOS_AP_METRES_PER_SLICE));
    vec3 s = texture(atmos_ap_scatter_texture, vec3(u, v, w)).rgb;
    vec3 t = texture(atmos_ap_transmittance_texture, vec3(u, v, w)).rgb;
    if (d < d_first) {
        float f = d / d_first;
        s *= f;
        t = vec3(1.0) - (vec3(1.0) - t) * f;
    }
    scatter = s;
    trans = t;
    return true;
}

// HillaireEvaluator::Evaluate: per unit solar irradiance, the sky along the
// ray, the lit ground attenuated to the camera, the segment's transmittance.
// Inside the atmosphere it reads the frame's tables (passes 1 and 2), outside
// it marches ATMOS_STEPS segments.
void atmos_Evaluate(vec3 camera, vec3 dir, vec3 sun, out vec3 sky, out vec3 ground,
                    out vec3 transmittance, out bool hits_ground) {
    float t_start, t_end;
    if (!atmos_BeginRay(camera, dir, sky, ground, transmittance, hits_ground, t_start, t_end)) {
        // A camera on the ground looking down sees the lit ground at its feet
        // through no air (physics/ray.h GroundAtCamera).
        if (hits_ground && atmos_GroundReflects()) ground = atmos_GroundReflection(camera, sun);
        return;
    }
    float r = length(camera);
    vec3 L = vec3(0.0), T = vec3(1.0);
    if (r <= ATMOS_TOP_RADIUS) {
        float mu = atmos_ClampCosine(dot(dir, camera) / r);
        if (!hits_ground) {
            L = atmos_SkyView(camera, dir, sun);
            T = atmos_Transmittance(r, mu);
        } else {
            float w = 1.0;
            if (ATMOS_GROUND_FROM_AP != 0 && atmos_AerialPerspective(dir, t_end, L, T)) {
                float d0 = atmos_ApSliceDistance(ATMOS_AP_BLEND_SLICE);
                float d1 = atmos_ApSliceDistance(ATMOS_AP_SIZE - 1);
                w = clamp((t_end - d0) / (d1 - d0), 0.0, 1.0);
            }
            if (w > 0.0) {
                vec3 Ls = atmos_SkyView(camera, dir, sun);
                vec3 Ts = atmos_TransmittanceToGround(r, mu, t_end);
                L = L * (1.0 - w) + Ls * w;
                T = T * (1.0 - w) + Ts * w;
            }
        }
    } else {
        atmos_Integrate(camera, dir, sun, t_start, t_end, ATMOS_STEPS, L, T, false);
    }
    sky = L;
    transmittance = T;
    if (hits_ground && atmos_GroundReflects()) {
        ground = atmos_GroundReflection(camera + dir * t_end, sun) * T;
    }
}
