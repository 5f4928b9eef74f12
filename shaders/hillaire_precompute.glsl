// atmos shaders: the `hillaire` model's baked tables computed on the GPU
// (issue 35 item 3): the transmittance table and the multiple-scattering
// table Psi_ms, as fragment-shader passes (GLSL ES 3.00 and GLSL 3.30 core).
//
// Written for atmos from the paper's math and our C++ code; each pass names
// the stage of src/atmos/models/hillaire_stages.h it mirrors (the arithmetic of
// HillaireTransmittanceStage and HillaireMultipleScatteringStage, in float).
// It is not the paper's demo code.
//
// Use: the bake JSON's "gpu_precompute" (src/atmos/io/gpu_passes.h) lists the
// passes and the files to concatenate after the #version line, the precision
// lines (ES) and the pass's "#define ENTRY 1": DIR/shaders/hillaire_constants.glsl,
// common.glsl, hillaire.glsl (its lookups: atmos_SunTransmittance,
// atmos_GroundReflection), then this file. Two passes, each one full-screen
// triangle into an RGBA32F (or RGBA16F) render target, texel (i, j) at
// gl_FragCoord.xy:
//   ATMOS_HILLAIRE_TRANSMITTANCE          -> "transmittance", 256 x 64, no input;
//   ATMOS_HILLAIRE_MULTIPLE_SCATTERING    -> "multiple_scattering", 32 x 32,
//       reads atmos_transmittance_texture (the first pass's target).
// .rgb is the table's RGB (what the CPU bake writes to "raw"), .a is 1.
//
// Precision: the C++ computes in double, this in float. Altitudes along a
// march are taken from r^2 - R^2 = rho^2 + t (2 r mu + t) (no cancellation of
// |p| - R at 6.4e6 m, which would lose ~0.4 m), so the tables agree with the
// CPU's to float rounding (docs/gpu.md gives the measured error).

out vec4 atmos_out;

// Texel sizes of the tables (kHillaireMsSize, kHillaireMsSqrtDirections,
// kHillaireMsSteps in hillaire.h).
const int ATMOS_MS_SIZE = 32;
const int ATMOS_MS_SQRT_DIRECTIONS = 8;
const int ATMOS_MS_STEPS = 20;

// Altitude of origin + t dir for an origin at radius r (r^2 - R^2 = rho2) and
// a direction of zenith cosine mu: (r_p^2 - R^2) / (r_p + R); also r_p.
float atmos_MarchAltitude(float rho2, float r, float mu, float t, out float r_p) {
    float q = rho2 + t * (2.0 * r * mu + t);
    r_p = sqrt(max(q + ATMOS_BOTTOM_RADIUS * ATMOS_BOTTOM_RADIUS, 0.0));
    return max(q, 0.0) / (r_p + ATMOS_BOTTOM_RADIUS);
}

// Extinction (physics/density.h Extinction) at an altitude.
vec3 atmos_ExtinctionAt(float altitude) {
    vec3 d = atmos_Densities(altitude);
    return ATMOS_RAYLEIGH_SCATTERING * d.x + ATMOS_MIE_EXTINCTION * d.y +
           ATMOS_ABSORPTION_EXTINCTION * d.z;
}

// ---- passes ----
// (Above: helpers every pass shares; below: each pass's main(). The Vulkan
// stage, src/atmos/io/engine_shaders.cpp PrecomputeStage, splits here.)

#ifdef ATMOS_HILLAIRE_TRANSMITTANCE
// HillaireTransmittanceStage (Bruneton's 2017 implementation notes
// ComputeTransmittanceToTopAtmosphereBoundaryTexture): texel (i, j) is
// (x_mu, x_r) = (i / (W - 1), j / (H - 1)) mapped to (r, mu) by
// HillaireTransmittanceRMu, then exp(-optical depth to the top) by the
// midpoint rule with ATMOS_TRANSMITTANCE_STEPS segments.
void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    float x_mu = float(texel.x) / float(ATMOS_TRANSMITTANCE_WIDTH - 1);
    float x_r = float(texel.y) / float(ATMOS_TRANSMITTANCE_HEIGHT - 1);
    float H = sqrt((ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS) * (ATMOS_TOP_RADIUS + ATMOS_BOTTOM_RADIUS));
    float rho = H * x_r;
    float rho2 = rho * rho;
    float r = sqrt(rho2 + ATMOS_BOTTOM_RADIUS * ATMOS_BOTTOM_RADIUS);
    // top - r without cancellation: (top^2 - R^2 - rho^2) / (top + r).
    float d_min = (H - rho) * (H + rho) / (ATMOS_TOP_RADIUS + r);
    float d_max = rho + H;
    float d = d_min + x_mu * (d_max - d_min);
    // mu = (H^2 - rho^2 - d^2) / (2 r d), with H^2 - rho^2 = top^2 - r^2.
    float mu = d == 0.0 ? 1.0 : atmos_ClampCosine(((H - rho) * (H + rho) - d * d) / (2.0 * r * d));
    // DistanceToTopAtmosphereBoundary(r, mu) is d itself (the mapping's).
    float dt = d / float(ATMOS_TRANSMITTANCE_STEPS);
    vec3 tau = vec3(0.0);
    for (int k = 0; k < ATMOS_TRANSMITTANCE_STEPS; ++k) {
        float r_p;
        tau += atmos_ExtinctionAt(atmos_MarchAltitude(rho2, r, mu, (float(k) + 0.5) * dt, r_p));
    }
    atmos_out = vec4(exp(-(tau * dt)), 1.0);
}
#endif

#ifdef ATMOS_HILLAIRE_MULTIPLE_SCATTERING
// HillaireMultipleScatteringStage (paper section 5.5.2, Eq. 5-10): texel
// (i, j) is mu_s = -1 + 2 i / 31 and r = R + (top - R) j / 31; 64 directions
// (8 x 8 stratified cell centres, uniform on the sphere) each marched in
// ATMOS_MS_STEPS segments sampled at ATMOS_SEGMENT_OFFSET of their length,
// accumulating L' (sun light scattered once, isotropic phase, and the lit
// ground) and f_ms; Psi_ms = mean(L') / (1 - mean(f_ms)).
void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    float p_u = 1.0 / (4.0 * ATMOS_PI);
    float mu_s = -1.0 + 2.0 * float(texel.x) / float(ATMOS_MS_SIZE - 1);
    float h = (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS) * float(texel.y) / float(ATMOS_MS_SIZE - 1);
    float r = ATMOS_BOTTOM_RADIUS + h;
    float rho2 = h * (h + 2.0 * ATMOS_BOTTOM_RADIUS);
    vec3 x = vec3(0.0, 0.0, r);
    vec3 sun = vec3(atmos_SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    vec3 l_2nd = vec3(0.0), f_ms = vec3(0.0);
    for (int k = 0; k < ATMOS_MS_SQRT_DIRECTIONS * ATMOS_MS_SQRT_DIRECTIONS; ++k) {
        float a = (float(k / ATMOS_MS_SQRT_DIRECTIONS) + 0.5) / float(ATMOS_MS_SQRT_DIRECTIONS);
        float b = (float(k - (k / ATMOS_MS_SQRT_DIRECTIONS) * ATMOS_MS_SQRT_DIRECTIONS) + 0.5) /
                  float(ATMOS_MS_SQRT_DIRECTIONS);
        float phi = 2.0 * ATMOS_PI * a;
        float cos_theta = 1.0 - 2.0 * b;
        float sin_theta = atmos_SafeSqrt(1.0 - cos_theta * cos_theta);
        vec3 dir = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
        float t_start, t_end;
        bool hits_ground;
        bool inside = atmos_ClipToAtmosphere(x, dir, t_start, t_end, hits_ground);
        vec3 L = vec3(0.0), F = vec3(0.0), T = vec3(1.0);
        if (inside) {
            float dt = (t_end - t_start) / float(ATMOS_MS_STEPS);
            for (int s = 0; s < ATMOS_MS_STEPS; ++s) {
                float t = t_start + (float(s) + ATMOS_SEGMENT_OFFSET) * dt;
                float r_p;
                float altitude = atmos_MarchAltitude(rho2, r, cos_theta, t, r_p);
                vec3 p = x + dir * t;
                vec3 d = atmos_Densities(altitude);
                vec3 sigma_s = ATMOS_RAYLEIGH_SCATTERING * d.x + ATMOS_MIE_SCATTERING * d.y;
                vec3 sigma_t = ATMOS_RAYLEIGH_SCATTERING * d.x + ATMOS_MIE_EXTINCTION * d.y +
                               ATMOS_ABSORPTION_EXTINCTION * d.z;
                vec3 t_sun = atmos_SunTransmittance(r_p, atmos_ClampCosine(dot(p, sun) / r_p));
                vec3 S = sigma_s * t_sun * p_u;
                vec3 step_t = exp(-sigma_t * dt);
                for (int c = 0; c < 3; ++c) {
                    float w = sigma_t[c] > 0.0 ? (1.0 - step_t[c]) / sigma_t[c] : dt;
                    L[c] += T[c] * S[c] * w;
                    F[c] += T[c] * sigma_s[c] * w;
                }
                T *= step_t;
            }
        }
        if (hits_ground) L += T * atmos_GroundReflection(x + dir * t_end, sun);
        l_2nd += L;
        f_ms += F;
    }
    float n = float(ATMOS_MS_SQRT_DIRECTIONS * ATMOS_MS_SQRT_DIRECTIONS);
    l_2nd /= n;
    f_ms /= n;
    atmos_out = vec4(l_2nd / max(vec3(1.0) - f_ms, vec3(1e-6)), 1.0);
}
#endif
