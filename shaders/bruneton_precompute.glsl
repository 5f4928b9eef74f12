// atmos shaders: the `bruneton` model's precomputation as GPU passes (issue 35
// item 3; docs/engine.md, "Tables computed on the GPU"). GLSL ES 3.00 and GLSL
// 3.30 core: no extensions.
//
// Written for atmos from the math of Bruneton 2017 and our C++: every pass
// names the stage of src/atmos/models/bruneton_stages.h it mirrors (the CPU
// and CUDA precomputation, bruneton_precompute.cpp). It is not Bruneton's
// published GLSL.
//
// Use: the bake's JSON "gpu_precompute" lists the passes, their render targets
// and the samplers each reads. A program is, in this order: the #version line
// (and, GLSL ES, `precision highp float; precision highp int;
// precision highp sampler3D;`), the pass's `#define ENTRY 1` line, then
// DIR/shaders/bruneton_constants.glsl, common.glsl, bruneton.glsl (its lookups)
// and this file. Each pass draws one full-screen triangle per layer of its
// RGBA32F target (uniform atmos_layer) and writes atmos_out per texel; the
// fragment's texel is (gl_FragCoord.xy, atmos_layer).
//
// Tables (RGBA32F targets; .rgb as the CPU's 3-channel tables):
//   transmittance      TW x TH        T(r, mu) to the top
//   delta_irradiance   IW x IH        direct, then indirect irradiance of one order
//   irradiance         IW x IH        the sum of the indirect orders (the bake's table)
//   delta_rayleigh     W x MU x R     single Rayleigh (W = NU * MU_S)
//   delta_mie          W x MU x R     single Mie
//   scattering         W x MU x R     Rayleigh + multiple / RayleighPhase (.a: Mie red,
//                                     combined storage)
//   single_mie_scattering             single Mie (separate storage)
//   directions         512 x 1        the scattering density's incident directions
//                                     (.rgb) and solid angles (.a)
//   incident           512 x MU_S x R incident radiance per direction, times its solid
//                                     angle (BrunetonIncidentStage)
//   delta_density      W x MU x R     the scattering density J_n
//   delta_multiple     W x MU x R     multiple scattering of order n
//
// Precision: the C++ computes geometry in double and tables in float; here
// everything is float. Altitudes along rays are computed from r^2 - bottom^2
// (no cancellation of r at 6.4e6 m); docs/engine.md gives the agreement.

uniform int atmos_layer;
out vec4 atmos_out;

// The samplers of the precomputation's own targets (those the renderer's
// bruneton.glsl does not declare): each pass reads those its "inputs" name.
uniform highp sampler3D atmos_delta_rayleigh_texture;
uniform highp sampler3D atmos_delta_mie_texture;
uniform highp sampler3D atmos_delta_multiple_texture;
uniform highp sampler3D atmos_delta_density_texture;
uniform highp sampler3D atmos_incident_texture;
uniform highp sampler2D atmos_directions_texture;
uniform highp sampler2D atmos_source_2d;  // ATMOS_PASS_COPY_2D
uniform highp sampler3D atmos_source_3d;  // ATMOS_PASS_ACCUMULATE

// kBrunetonTransmittanceSamples, kBrunetonDensityThetaSamples,
// kBrunetonIrradianceSamples, kThickStepOpticalDepth, kThickRaySubsteps.
const int ATMOS_TRANSMITTANCE_SAMPLES = 500;
const int ATMOS_DENSITY_THETA_SAMPLES = 16;
const int ATMOS_DIRECTIONS = 512;  // 16 theta x 32 phi
const int ATMOS_IRRADIANCE_SAMPLES = 32;
const float ATMOS_THICK_STEP_OPTICAL_DEPTH = 1.0;
const int ATMOS_THICK_RAY_SUBSTEPS = 8;
// ATMOS_SCATTERING_SAMPLES and ATMOS_SCATTERING_RULE (the view-ray quadrature:
// BrunetonConfig's scattering_samples and scattering_rule) come with the constants.

// GetUnitRangeFromTextureCoord (base/texture.h): the inverse of atmos_TextureCoord.
float atmos_UnitRange(float u, float n) { return (u - 0.5 / n) / (1.0 - 1.0 / n); }

// The altitude at distance t along the ray from radius r (rho2 = r^2 -
// bottom^2) of zenith cosine mu: the C++'s Length(origin + dir t) - bottom,
// from r_t^2 - bottom^2 without forming r_t^2.
float atmos_AltitudeAlong(float r, float rho2, float mu, float t) {
    float q = max(t * (t + 2.0 * r * mu) + rho2, 0.0);
    return q / (sqrt(q + ATMOS_BOTTOM_RADIUS * ATMOS_BOTTOM_RADIUS) + ATMOS_BOTTOM_RADIUS);
}
// Extinction(GetDensities(altitude)) (physics/density.h).
vec3 atmos_ExtinctionAt(float altitude) {
    vec3 d = atmos_Densities(altitude);
    return ATMOS_RAYLEIGH_SCATTERING * d.x + ATMOS_MIE_EXTINCTION * d.y +
           ATMOS_ABSORPTION_EXTINCTION * d.z;
}
float atmos_MaxComponent(vec3 v) { return max(v.x, max(v.y, v.z)); }

// BrunetonQuadratureWeight: the trapezoid (rule 0) or composite Simpson with
// Simpson's 3/8 rule on the last three intervals for odd n.
float atmos_QuadratureWeight(int i, int n) {
    if (ATMOS_SCATTERING_RULE == 0 || n < 2) return (i == 0 || i == n) ? 0.5 : 1.0;
    int m = (n % 2 == 0) ? n : n - 3;
    float w = 0.0;
    if (i <= m && m > 0) {
        w += (i == 0 || i == m) ? 1.0 / 3.0 : ((i % 2 == 1) ? 4.0 / 3.0 : 2.0 / 3.0);
    }
    if (i >= m && m != n) w += (i == m || i == n) ? 3.0 / 8.0 : 9.0 / 8.0;
    return w;
}


// ---- lookups from (r, rho) (rho = sqrt(r^2 - bottom^2) = atmos_Rho(r)) ----
// bruneton.glsl's lookups take r alone and form rho from it: near the ground
// r's float rounding (0.5 m at 6.4e6 m) is a large part of r - bottom, and
// grazing rays' transmittance depends steeply on rho. The precomputation knows
// each sample's altitude exactly (atmos_AltitudeAlong), so these forms take rho
// from it; otherwise the same operations as bruneton.glsl (the C++ has double).

// rho of an altitude: sqrt(alt (alt + 2 bottom)).
float atmos_RhoOfAltitude(float alt) {
    return sqrt(max(alt * (alt + 2.0 * ATMOS_BOTTOM_RADIUS), 0.0));
}
// atmos_TransmittanceToTop (BrunetonLut::TransmittanceToTop).
vec3 atmos_TransmittanceToTopRho(float r, float rho, float mu) {
    mu = atmos_ClampCosine(mu);
    float H = atmos_HorizonH();
    float d = atmos_DistanceToTop(r, mu);
    float d_min = ATMOS_TOP_RADIUS - r;
    float d_max = rho + H;
    float x_mu = (d - d_min) / (d_max - d_min);
    vec2 uv = vec2(atmos_TextureCoord(x_mu, float(ATMOS_TRANSMITTANCE_WIDTH)),
                   atmos_TextureCoord(rho / H, float(ATMOS_TRANSMITTANCE_HEIGHT)));
    return texture(atmos_transmittance_texture, uv).rgb;
}
// atmos_Transmittance (BrunetonLut::Transmittance) between (r, mu) and the
// point at distance d (rho2 = rho^2).
vec3 atmos_TransmittanceRho(float r, float rho2, float mu, float d, bool ground) {
    float alt_d = min(atmos_AltitudeAlong(r, rho2, mu, d), ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
    float r_d = ATMOS_BOTTOM_RADIUS + alt_d;
    float rho_d = atmos_RhoOfAltitude(alt_d);
    float mu_d = atmos_ClampCosine((r * mu + d) / r_d);
    float rho = sqrt(rho2);
    if (ground) {
        return atmos_SafeRatio(atmos_TransmittanceToTopRho(r_d, rho_d, -mu_d),
                               atmos_TransmittanceToTopRho(r, rho, -mu));
    }
    return atmos_SafeRatio(atmos_TransmittanceToTopRho(r, rho, mu),
                           atmos_TransmittanceToTopRho(r_d, rho_d, mu_d));
}
// atmos_TransmittanceToSun (BrunetonLut::TransmittanceToSun); cos of the
// horizon angle -rho / r.
vec3 atmos_TransmittanceToSunRho(float r, float rho, float mu_s) {
    float sin_theta_h = ATMOS_BOTTOM_RADIUS / r;
    float cos_theta_h = -rho / r;
    float a = sin_theta_h * ATMOS_SUN_ANGULAR_RADIUS;
    float f = atmos_SmoothStep(-a, a, mu_s - cos_theta_h);
    if (f <= 0.0) return vec3(0.0);
    return atmos_TransmittanceToTopRho(r, rho, mu_s) * f;
}
// atmos_ScatteringUvwz (BrunetonLut::ScatteringUvwz), clamped as GetScattering.
vec4 atmos_ScatteringUvwzRho(float r, float rho, float mu, float mu_s, float nu, bool ground) {
    mu = atmos_ClampCosine(mu);
    vec4 uvwz = atmos_ScatteringUvwz(r, mu, atmos_ClampCosine(mu_s), atmos_ClampCosine(nu), ground);
    float H = atmos_HorizonH();
    uvwz.w = atmos_TextureCoord(rho / H, float(ATMOS_SCATTERING_R));
    float r_mu = r * mu;
    float disc = r_mu * r_mu - rho * rho;
    float half_mu = float(ATMOS_SCATTERING_MU / 2);
    if (ground) {
        float d = -r_mu - atmos_SafeSqrt(disc);
        float d_min = rho * rho / (r + ATMOS_BOTTOM_RADIUS);  // r - bottom
        float d_max = rho;
        float x = d_max == d_min ? 0.0 : (d - d_min) / (d_max - d_min);
        uvwz.z = 0.5 - 0.5 * atmos_TextureCoord(x, half_mu);
    } else {
        float d = -r_mu + atmos_SafeSqrt(disc + H * H);
        float d_min = ATMOS_TOP_RADIUS - r;
        float d_max = rho + H;
        uvwz.z = 0.5 + 0.5 * atmos_TextureCoord((d - d_min) / (d_max - d_min), half_mu);
    }
    return uvwz;
}

// ---- the scattering texel (BrunetonLut::RMuMuSNuFromTexel) ----

struct atmos_ScatteringTexel {
    float r, rho2, mu, mu_s, nu;
    bool ground;
};
// r of the scattering table's layer z (and rho^2 = r^2 - bottom^2).
void atmos_RadiusOfLayer(int z, out float r, out float rho2) {
    float H = atmos_HorizonH();
    float rho = H * atmos_UnitRange((float(z) + 0.5) / float(ATMOS_SCATTERING_R),
                                    float(ATMOS_SCATTERING_R));
    rho2 = rho * rho;
    r = sqrt(rho2 + ATMOS_BOTTOM_RADIUS * ATMOS_BOTTOM_RADIUS);
}
// mu_s of the scattering table's mu_s column s (RMuMuSNuFromScatteringUvwz).
float atmos_MuSOfColumn(int s) {
    float H = atmos_HorizonH();
    float d_min = ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS;
    float d_range = H - d_min;
    float D = atmos_DistanceToTop(ATMOS_BOTTOM_RADIUS, ATMOS_MU_S_MIN);
    float A = (D - d_min) / d_range;
    float x_mu_s = atmos_UnitRange((float(s) + 0.5) / float(ATMOS_SCATTERING_MU_S),
                                   float(ATMOS_SCATTERING_MU_S));
    float a = (A - x_mu_s * A) / (1.0 + x_mu_s * A);
    float d = d_min + min(a, A) * d_range;
    return d == 0.0 ? 1.0 : atmos_ClampCosine((H * H - d * d) / (2.0 * ATMOS_BOTTOM_RADIUS * d));
}
// BrunetonLut::ClampNu.
float atmos_ClampNu(float nu, float mu, float mu_s) {
    float s = atmos_SafeSqrt((1.0 - mu * mu) * (1.0 - mu_s * mu_s));
    return clamp(nu, mu * mu_s - s, mu * mu_s + s);
}
atmos_ScatteringTexel atmos_ScatteringTexelOf(ivec3 p) {
    atmos_ScatteringTexel t;
    int nu_index = p.x / ATMOS_SCATTERING_MU_S;
    int mu_s_index = p.x - nu_index * ATMOS_SCATTERING_MU_S;
    atmos_RadiusOfLayer(p.z, t.r, t.rho2);
    float rho = sqrt(t.rho2);
    float H = atmos_HorizonH();
    float u_mu = (float(p.y) + 0.5) / float(ATMOS_SCATTERING_MU);
    float half_mu = float(ATMOS_SCATTERING_MU / 2);
    if (u_mu < 0.5) {
        float d_min = t.rho2 / (t.r + ATMOS_BOTTOM_RADIUS);  // r - bottom
        float d_max = rho;
        float d = d_min + (d_max - d_min) * atmos_UnitRange(1.0 - 2.0 * u_mu, half_mu);
        t.mu = d == 0.0 ? -1.0 : atmos_ClampCosine(-(t.rho2 + d * d) / (2.0 * t.r * d));
        t.ground = true;
    } else {
        float d_min = ATMOS_TOP_RADIUS - t.r;
        float d_max = rho + H;
        float d = d_min + (d_max - d_min) * atmos_UnitRange(2.0 * u_mu - 1.0, half_mu);
        // H^2 - rho^2 = top^2 - r^2.
        float top2_r2 = (ATMOS_TOP_RADIUS - t.r) * (ATMOS_TOP_RADIUS + t.r);
        t.mu = d == 0.0 ? 1.0 : atmos_ClampCosine((top2_r2 - d * d) / (2.0 * t.r * d));
        t.ground = false;
    }
    t.mu_s = atmos_MuSOfColumn(mu_s_index);
    float u_nu = ATMOS_SCATTERING_NU > 1 ? float(nu_index) / float(ATMOS_SCATTERING_NU - 1) : 0.5;
    t.nu = atmos_ClampNu(atmos_ClampCosine(u_nu * 2.0 - 1.0), t.mu, t.mu_s);
    return t;
}
// DistanceToBottomAtmosphereBoundary, the discriminant (r mu)^2 - rho^2.
float atmos_DistanceToBottomRho(float r, float rho2, float mu) {
    return max(-r * mu - atmos_SafeSqrt((r * mu) * (r * mu) - rho2), 0.0);
}
// BrunetonLut::DistanceToNearestAtmosphereBoundary.
float atmos_DistanceToNearest(float r, float rho2, float mu, bool ground) {
    return ground ? atmos_DistanceToBottomRho(r, rho2, mu) : atmos_DistanceToTop(r, mu);
}

// ---- optically thick steps (physics/exp_quadrature.h) ----

// RayHasThickSteps: a node of the ray (r, mu) every ds (n intervals) whose
// extinction times ds exceeds ATMOS_THICK_STEP_OPTICAL_DEPTH.
bool atmos_RayHasThickSteps(float r, float rho2, float mu, float ds, int n) {
    for (int i = 0; i <= n; ++i) {
        float alt = atmos_AltitudeAlong(r, rho2, mu, float(i) * ds);
        if (atmos_MaxComponent(atmos_ExtinctionAt(alt)) * ds > ATMOS_THICK_STEP_OPTICAL_DEPTH) {
            return true;
        }
    }
    return false;
}
// SegmentOpticalDepth: trapezoid in ATMOS_THICK_RAY_SUBSTEPS sub-intervals.
vec3 atmos_SegmentOpticalDepth(float r, float rho2, float mu, float s0, float s1) {
    float h = (s1 - s0) / float(ATMOS_THICK_RAY_SUBSTEPS);
    vec3 sum = vec3(0.0);
    for (int k = 0; k <= ATMOS_THICK_RAY_SUBSTEPS; ++k) {
        float w = (k == 0 || k == ATMOS_THICK_RAY_SUBSTEPS) ? 0.5 : 1.0;
        sum += atmos_ExtinctionAt(atmos_AltitudeAlong(r, rho2, mu, s0 + float(k) * h)) * w;
    }
    return sum * h;
}
// ExpLinearWeights: a(dtau), b(dtau) of the exponential-linear rule.
void atmos_ExpLinearWeights(float dtau, out float a, out float b) {
    if (dtau < 1e-3) {
        a = dtau * (0.5 - dtau / 6.0);
        b = dtau * (0.5 - dtau / 3.0);
        return;
    }
    float e = exp(-dtau);
    b = (1.0 - (1.0 + dtau) * e) / dtau;
    a = (1.0 - e) - b;
}
// ThickRayWeights: the node weights W_i / sigma_t,i, node by node (state in
// t and carry, which start at 1 and 0).
vec3 atmos_ThickRayWeightNext(float r, float rho2, float mu, float ds, int n, int i,
                              inout vec3 t, inout vec3 carry) {
    vec3 dtau = i < n ? atmos_SegmentOpticalDepth(r, rho2, mu, float(i) * ds, float(i + 1) * ds)
                      : vec3(0.0);
    vec3 w;
    for (int c = 0; c < 3; ++c) {
        float a, b;
        atmos_ExpLinearWeights(dtau[c], a, b);
        w[c] = carry[c] + t[c] * a;
        carry[c] = t[c] * b;
        t[c] *= exp(-dtau[c]);
    }
    vec3 sigma_t = atmos_ExtinctionAt(atmos_AltitudeAlong(r, rho2, mu, float(i) * ds));
    vec3 out_w;
    for (int c = 0; c < 3; ++c) out_w[c] = sigma_t[c] > 0.0 ? w[c] / sigma_t[c] : 0.0;
    return out_w;
}

// ---- passes ----

#ifdef ATMOS_PASS_TRANSMITTANCE
// BrunetonTransmittanceStage: exp(-optical depth to the top), the trapezoid in
// 500 intervals (OpticalDepthToTopAtmosphereBoundary).
void main() {
    vec2 uv = gl_FragCoord.xy / vec2(ATMOS_TRANSMITTANCE_WIDTH, ATMOS_TRANSMITTANCE_HEIGHT);
    float x_mu = atmos_UnitRange(uv.x, float(ATMOS_TRANSMITTANCE_WIDTH));
    float x_r = atmos_UnitRange(uv.y, float(ATMOS_TRANSMITTANCE_HEIGHT));
    float H = atmos_HorizonH();
    float rho = H * x_r;
    float rho2 = rho * rho;
    float r = sqrt(rho2 + ATMOS_BOTTOM_RADIUS * ATMOS_BOTTOM_RADIUS);
    float d_min = ATMOS_TOP_RADIUS - r;
    float d_max = rho + H;
    float d = d_min + x_mu * (d_max - d_min);
    float top2_r2 = (ATMOS_TOP_RADIUS - r) * (ATMOS_TOP_RADIUS + r);
    float mu = d == 0.0 ? 1.0 : atmos_ClampCosine((top2_r2 - d * d) / (2.0 * r * d));
    int n = ATMOS_TRANSMITTANCE_SAMPLES;
    float dx = atmos_DistanceToTop(r, mu) / float(n);
    vec3 sum = vec3(0.0);
    for (int i = 0; i <= n; ++i) {
        float w = (i == 0 || i == n) ? 0.5 : 1.0;
        sum += atmos_ExtinctionAt(atmos_AltitudeAlong(r, rho2, mu, float(i) * dx)) * w;
    }
    atmos_out = vec4(exp(-sum * dx), 1.0);
}
#endif

#ifdef ATMOS_PASS_DIRECT_IRRADIANCE
// BrunetonDirectIrradianceStage (BrunetonLut::DirectIrradiance): the average
// cosine over the sun's visible disc times the transmittance to the top.
void main() {
    vec2 uv = gl_FragCoord.xy / vec2(ATMOS_IRRADIANCE_WIDTH, ATMOS_IRRADIANCE_HEIGHT);
    float x_mu_s = atmos_UnitRange(uv.x, float(ATMOS_IRRADIANCE_WIDTH));
    float x_r = atmos_UnitRange(uv.y, float(ATMOS_IRRADIANCE_HEIGHT));
    float r = ATMOS_BOTTOM_RADIUS + x_r * (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
    float mu_s = atmos_ClampCosine(2.0 * x_mu_s - 1.0);
    float alpha_s = ATMOS_SUN_ANGULAR_RADIUS;
    float c = mu_s < -alpha_s
                  ? 0.0
                  : (mu_s > alpha_s ? mu_s : (mu_s + alpha_s) * (mu_s + alpha_s) / (4.0 * alpha_s));
    float alt = x_r * (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
    atmos_out = vec4(atmos_TransmittanceToTopRho(r, atmos_RhoOfAltitude(alt), mu_s) * c, 1.0);
}
#endif

#if defined(ATMOS_PASS_SINGLE_RAYLEIGH) || defined(ATMOS_PASS_SINGLE_MIE)
// BrunetonSingleScatteringStage: the single Rayleigh (or Mie) scattering of the
// texel, without phase function: sum over the view ray's samples of the
// transmittance to the sun times the transmittance from the camera, the
// density and the quadrature weight (the exponential-linear rule's weights on
// a ray with optically thick steps), times beta dx.
void main() {
    atmos_ScatteringTexel t = atmos_ScatteringTexelOf(ivec3(gl_FragCoord.xy, atmos_layer));
    int n = ATMOS_SCATTERING_SAMPLES;
    float dx = atmos_DistanceToNearest(t.r, t.rho2, t.mu, t.ground) / float(n);
    bool thick = atmos_RayHasThickSteps(t.r, t.rho2, t.mu, dx, n);
    vec3 thick_t = vec3(1.0), thick_carry = vec3(0.0);
    vec3 sum = vec3(0.0);
    for (int i = 0; i <= n; ++i) {
        float d = float(i) * dx;
        float alt = min(atmos_AltitudeAlong(t.r, t.rho2, t.mu, d),
                        ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
        float r_i = ATMOS_BOTTOM_RADIUS + alt;
        float rho_i = atmos_RhoOfAltitude(alt);
        vec3 d_rm = atmos_Densities(alt);
#ifdef ATMOS_PASS_SINGLE_RAYLEIGH
        float density = d_rm.x;
#else
        float density = d_rm.y;
#endif
        vec3 weight;
        if (thick) {
            weight = atmos_ThickRayWeightNext(t.r, t.rho2, t.mu, dx, n, i, thick_t, thick_carry) *
                     (density / dx);
        } else {
            weight = atmos_TransmittanceRho(t.r, t.rho2, t.mu, d, t.ground) *
                     (density * atmos_QuadratureWeight(i, n));
        }
        float mu_s_i = atmos_ClampCosine((t.r * t.mu_s + d * t.nu) / r_i);
        sum += atmos_TransmittanceToSunRho(r_i, rho_i, mu_s_i) * weight;
    }
#ifdef ATMOS_PASS_SINGLE_RAYLEIGH
    atmos_out = vec4(sum * (ATMOS_RAYLEIGH_SCATTERING * dx), 1.0);
#else
    atmos_out = vec4(sum * (ATMOS_MIE_SCATTERING * dx), 1.0);
#endif
}
#endif

#ifdef ATMOS_PASS_SINGLE_TO_SCATTERING
// BrunetonCombineStage: the scattering table after order 1 (single Rayleigh;
// alpha: single Mie red, used with combined storage).
void main() {
    ivec3 p = ivec3(gl_FragCoord.xy, atmos_layer);
    atmos_out = vec4(texelFetch(atmos_delta_rayleigh_texture, p, 0).rgb,
                     texelFetch(atmos_delta_mie_texture, p, 0).r);
}
#endif

#ifdef ATMOS_PASS_COPY_3D
// BrunetonCombineStage's single Mie table (separate storage): a copy.
void main() {
    atmos_out = texelFetch(atmos_source_3d, ivec3(gl_FragCoord.xy, atmos_layer), 0);
}
#endif

#ifdef ATMOS_PASS_COPY_2D
// BrunetonAddStage: the irradiance of one order, copied ("replace") or added
// ("add") to the irradiance table.
void main() { atmos_out = vec4(texelFetch(atmos_source_2d, ivec2(gl_FragCoord.xy), 0).rgb, 0.0); }
#endif

#ifdef ATMOS_PASS_ZERO
// An irradiance table without indirect light (orders = 1).
void main() { atmos_out = vec4(0.0); }
#endif

#ifdef ATMOS_PASS_DIRECTIONS
// MakeBrunetonDirectionTable: direction k = l * 32 + m of the 16 x 32 midpoint
// grid (theta, phi), in the sun's frame, and its solid angle.
void main() {
    int k = int(gl_FragCoord.x);
    int l = k / (2 * ATMOS_DENSITY_THETA_SAMPLES);
    int m = k - l * (2 * ATMOS_DENSITY_THETA_SAMPLES);
    float dtheta = ATMOS_PI / float(ATMOS_DENSITY_THETA_SAMPLES);
    float dphi = dtheta;
    float theta = (float(l) + 0.5) * dtheta;
    float phi = (float(m) + 0.5) * dphi;
    atmos_out = vec4(cos(phi) * sin(theta), sin(phi) * sin(theta), cos(theta),
                     dtheta * dphi * sin(theta));
}
#endif

#if defined(ATMOS_PASS_INCIDENT_SINGLE) || defined(ATMOS_PASS_INCIDENT_MULTIPLE)
// BrunetonIncidentStage: the radiance arriving at (r, mu_s) from direction k
// after n - 1 bounces (order 2: the single Rayleigh and Mie tables with their
// phase functions; n > 2: the multiple scattering of order n - 1), plus the
// light of the ground (Lambertian, from the irradiance of order n - 2), times
// the direction's solid angle. Texel (k, mu_s column, r layer).
void main() {
    ivec3 p = ivec3(gl_FragCoord.xy, atmos_layer);
    int k = p.x;
    float r, rho2;
    atmos_RadiusOfLayer(p.z, r, rho2);
    float mu_s = atmos_MuSOfColumn(p.y);
    vec3 omega_s = vec3(atmos_SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    int l = k / (2 * ATMOS_DENSITY_THETA_SAMPLES);
    int m = k - l * (2 * ATMOS_DENSITY_THETA_SAMPLES);
    float dtheta = ATMOS_PI / float(ATMOS_DENSITY_THETA_SAMPLES);
    float theta = (float(l) + 0.5) * dtheta;
    float phi = (float(m) + 0.5) * dtheta;
    float ct = cos(theta);
    // RayIntersectsGround.
    bool ground = ct < 0.0 && rho2 <= (r * ct) * (r * ct);
    vec3 omega_i = vec3(cos(phi) * sin(theta), sin(phi) * sin(theta), ct);
    float nu1 = atmos_ClampCosine(dot(omega_s, omega_i));
    vec4 uvwz = atmos_ScatteringUvwzRho(r, sqrt(rho2), ct, mu_s, nu1, ground);
#ifdef ATMOS_PASS_INCIDENT_SINGLE
    vec3 inc = atmos_Lookup4D(atmos_delta_rayleigh_texture, uvwz).rgb * atmos_RayleighPhase(nu1) +
               atmos_Lookup4D(atmos_delta_mie_texture, uvwz).rgb * atmos_MiePhase(nu1);
#else
    vec3 inc = atmos_Lookup4D(atmos_delta_multiple_texture, uvwz).rgb;
#endif
    if (ground && atmos_GroundReflects()) {
        float distance_to_ground = atmos_DistanceToBottomRho(r, rho2, ct);
        vec3 transmittance_to_ground =
            atmos_TransmittanceRho(r, rho2, ct, distance_to_ground, true);
        vec3 normal = normalize(vec3(0.0, 0.0, r) + omega_i * distance_to_ground);
        // atmos_irradiance_texture is the ground irradiance after n - 2 bounces here.
        vec3 e = atmos_GetIrradiance(ATMOS_BOTTOM_RADIUS, atmos_ClampCosine(dot(normal, omega_s)));
        inc += transmittance_to_ground * ATMOS_GROUND_ALBEDO * (1.0 / ATMOS_PI) * e;
    }
    atmos_out = vec4(inc * (dtheta * dtheta * sin(theta)), 1.0);
}
#endif

#ifdef ATMOS_PASS_SCATTERING_DENSITY
// BrunetonDensityStage: J_n at the texel, the incident radiance of its (r,
// mu_s) weighted by the phase functions of the angle to the view direction
// (omega.z = mu, omega.omega_s = nu in the sun's frame), times the scattering
// coefficients at r.
void main() {
    ivec3 p = ivec3(gl_FragCoord.xy, atmos_layer);
    atmos_ScatteringTexel t = atmos_ScatteringTexelOf(p);
    float sin_s = atmos_SafeSqrt(1.0 - t.mu_s * t.mu_s);
    float ox = sin_s == 0.0 ? 0.0 : (t.nu - t.mu * t.mu_s) / sin_s;
    float oy = atmos_SafeSqrt(1.0 - ox * ox - t.mu * t.mu);
    vec3 omega = vec3(ox, oy, t.mu);
    int s = p.x - (p.x / ATMOS_SCATTERING_MU_S) * ATMOS_SCATTERING_MU_S;
    vec3 sum_r = vec3(0.0), sum_m = vec3(0.0);
    for (int k = 0; k < ATMOS_DIRECTIONS; ++k) {
        vec3 w = texelFetch(atmos_directions_texture, ivec2(k, 0), 0).xyz;
        vec3 li = texelFetch(atmos_incident_texture, ivec3(k, s, p.z), 0).rgb;
        float x = dot(omega, w);
        sum_r += (1.0 + x * x) * li;
        sum_m += atmos_MiePhase(x) * li;
    }
    float alt = t.rho2 / (t.r + ATMOS_BOTTOM_RADIUS);
    vec3 d = atmos_Densities(alt);
    atmos_out = vec4(sum_r * (ATMOS_RAYLEIGH_SCATTERING * (d.x * (3.0 / (16.0 * ATMOS_PI)))) +
                         sum_m * (ATMOS_MIE_SCATTERING * d.y),
                     1.0);
}
#endif

#if defined(ATMOS_PASS_INDIRECT_IRRADIANCE_SINGLE) || defined(ATMOS_PASS_INDIRECT_IRRADIANCE_MULTIPLE)
// BrunetonIndirectIrradianceStage: the irradiance of a horizontal surface at
// (r, mu_s) from the sky after one bounce (from the single scattering tables)
// or after n (from the multiple scattering of order n): a 16 x 64 midpoint
// grid over the upper hemisphere.
void main() {
    vec2 uv = gl_FragCoord.xy / vec2(ATMOS_IRRADIANCE_WIDTH, ATMOS_IRRADIANCE_HEIGHT);
    float x_mu_s = atmos_UnitRange(uv.x, float(ATMOS_IRRADIANCE_WIDTH));
    float x_r = atmos_UnitRange(uv.y, float(ATMOS_IRRADIANCE_HEIGHT));
    float r = ATMOS_BOTTOM_RADIUS + x_r * (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
    float mu_s = atmos_ClampCosine(2.0 * x_mu_s - 1.0);
    float rho = atmos_RhoOfAltitude(x_r * (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS));
    vec3 omega_s = vec3(atmos_SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    int n = ATMOS_IRRADIANCE_SAMPLES;
    float dphi = ATMOS_PI / float(n);
    float dtheta = ATMOS_PI / float(n);
    vec3 sum = vec3(0.0);
    for (int j = 0; j < n / 2; ++j) {
        float theta = (float(j) + 0.5) * dtheta;
        float st = sin(theta), ct = cos(theta);
        float domega = dtheta * dphi * st;
        for (int i = 0; i < 2 * n; ++i) {
            float phi = (float(i) + 0.5) * dphi;
            vec3 omega = vec3(cos(phi) * st, sin(phi) * st, ct);
            float nu = atmos_ClampCosine(dot(omega, omega_s));
            vec4 uvwz = atmos_ScatteringUvwzRho(r, rho, omega.z, mu_s, nu, false);
#ifdef ATMOS_PASS_INDIRECT_IRRADIANCE_SINGLE
            vec3 l = atmos_Lookup4D(atmos_delta_rayleigh_texture, uvwz).rgb *
                         atmos_RayleighPhase(nu) +
                     atmos_Lookup4D(atmos_delta_mie_texture, uvwz).rgb * atmos_MiePhase(nu);
#else
            vec3 l = atmos_Lookup4D(atmos_delta_multiple_texture, uvwz).rgb;
#endif
            sum += l * (omega.z * domega);
        }
    }
    atmos_out = vec4(sum, 1.0);
}
#endif

#ifdef ATMOS_PASS_MULTIPLE_SCATTERING
// BrunetonMultipleScatteringStage: the multiple scattering of order n at the
// texel, the density J_n along the view ray times the transmittance from the
// camera and the quadrature weight (the exponential-linear rule's weights on a
// ray with optically thick steps).
void main() {
    atmos_ScatteringTexel t = atmos_ScatteringTexelOf(ivec3(gl_FragCoord.xy, atmos_layer));
    int n = ATMOS_SCATTERING_SAMPLES;
    float dx = atmos_DistanceToNearest(t.r, t.rho2, t.mu, t.ground) / float(n);
    bool thick = atmos_RayHasThickSteps(t.r, t.rho2, t.mu, dx, n);
    vec3 thick_t = vec3(1.0), thick_carry = vec3(0.0);
    vec3 sum = vec3(0.0);
    for (int i = 0; i <= n; ++i) {
        float d = float(i) * dx;
        float alt = min(atmos_AltitudeAlong(t.r, t.rho2, t.mu, d),
                        ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
        float r_i = ATMOS_BOTTOM_RADIUS + alt;
        float rho_i = atmos_RhoOfAltitude(alt);
        float mu_i = atmos_ClampCosine((t.r * t.mu + d) / r_i);
        float mu_s_i = atmos_ClampCosine((t.r * t.mu_s + d * t.nu) / r_i);
        vec3 weight;
        if (thick) {
            weight = atmos_ThickRayWeightNext(t.r, t.rho2, t.mu, dx, n, i, thick_t, thick_carry);
        } else {
            weight = atmos_TransmittanceRho(t.r, t.rho2, t.mu, d, t.ground) *
                     (atmos_QuadratureWeight(i, n) * dx);
        }
        vec4 uvwz = atmos_ScatteringUvwzRho(r_i, rho_i, mu_i, mu_s_i, t.nu, t.ground);
        sum += atmos_Lookup4D(atmos_delta_density_texture, uvwz).rgb * weight;
    }
    atmos_out = vec4(sum, 1.0);
}
#endif

#ifdef ATMOS_PASS_ACCUMULATE
// BrunetonAccumulateStage: scattering += delta_multiple / RayleighPhase(nu)
// (blend "add"; alpha, the combined storage's Mie red, gets 0).
void main() {
    ivec3 p = ivec3(gl_FragCoord.xy, atmos_layer);
    atmos_ScatteringTexel t = atmos_ScatteringTexelOf(p);
    atmos_out = vec4(texelFetch(atmos_source_3d, p, 0).rgb / atmos_RayleighPhase(t.nu), 0.0);
}
#endif
