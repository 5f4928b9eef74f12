// atmos shaders: math and geometry shared by every model's shader
// (GLSL ES 3.00 and GLSL 3.30 core: no extensions).
//
// Written for atmos from our C++ (include/atmos/math.h, src/atmos/physics/
// geometry.h, phase.h, density.h) and the math of Bruneton 2017;
// every function names the C++ function it mirrors. GLSL has no #include:
// `atmos bake` installs this file as DIR/shaders/common.glsl and a program
// concatenates, in this order,
//   1. the #version line and `precision highp float; precision highp sampler3D;`
//      (GLSL ES),
//   2. the bake's DIR/shaders/NAME_constants.glsl (ATMOS_BOTTOM_RADIUS,
//      ATMOS_TOP_RADIUS, ATMOS_MIE_PHASE_G, ...),
//   3. this file,
//   4. the model's DIR/shaders/NAME.glsl.
//
// Units: metres, planet-centred positions (the planet's centre is the origin).
// Precision: the C++ computes geometry in double; here float. The quadratic
// forms are rearranged as the C++ (IntersectSphere, RayIntersectsGround) to
// avoid the cancellation of r^2 - R^2 at 6.4e6 m.

const float ATMOS_PI = 3.14159265358979;

// SafeSqrt (math.h).
float atmos_SafeSqrt(float x) { return sqrt(max(x, 0.0)); }
// ClampCosine (math.h).
float atmos_ClampCosine(float mu) { return clamp(mu, -1.0, 1.0); }
// GetTextureCoordFromUnitRange (base/texture.h; Bruneton's 2017 implementation notes "Precomputation"):
// [0, 1] onto the texel centres of a texture of n texels.
float atmos_TextureCoord(float x, float n) { return 0.5 / n + x * (1.0 - 1.0 / n); }
// RayleighPhase (physics/phase.h; Bruneton's 2017 implementation notes RayleighPhaseFunction).
float atmos_RayleighPhase(float nu) { return 3.0 / (16.0 * ATMOS_PI) * (1.0 + nu * nu); }
// CornetteShanksPhase (phase.h; Bruneton's 2017 implementation notes MiePhaseFunction).
float atmos_CornetteShanksPhase(float g, float nu) {
    float k = 3.0 / (8.0 * ATMOS_PI) * (1.0 - g * g) / (2.0 + g * g);
    float denom = 1.0 + g * g - 2.0 * g * nu;
    return k * (1.0 + nu * nu) / (denom * sqrt(denom));
}
// HenyeyGreensteinPhase (phase.h).
float atmos_HenyeyGreensteinPhase(float g, float nu) {
    float denom = 1.0 + g * g - 2.0 * g * nu;
    return (1.0 - g * g) / (4.0 * ATMOS_PI * denom * sqrt(denom));
}
// The Mie phase's kind (atmosphere.h MiePhaseKind): the constants define it
// for every kind but Cornette-Shanks (0).
#ifndef ATMOS_MIE_PHASE_KIND
#define ATMOS_MIE_PHASE_KIND 0
#endif
// One lobe of the Mie phase: Henyey-Greenstein (kind 1) or Cornette-Shanks.
float atmos_MieLobe(float g, float nu) {
#if ATMOS_MIE_PHASE_KIND == 1
    return atmos_HenyeyGreensteinPhase(g, nu);
#else
    return atmos_CornetteShanksPhase(g, nu);
#endif
}
// MiePhase (phase.h): 2 isotropic; 3 tabulated (TabulatedPhase: the constants'
// atmos_MiePhaseTableMu and atmos_MiePhaseTableValue, linear in nu between
// nodes); else the lobe with g = ATMOS_MIE_PHASE_G, or, when the constants
// define ATMOS_MIE_PHASE_WEIGHT2 (a second lobe), (1 - w) lobe(ATMOS_MIE_PHASE_G)
// + w lobe(ATMOS_MIE_PHASE_G2).
float atmos_MiePhase(float nu) {
#if ATMOS_MIE_PHASE_KIND == 2
    return 1.0 / (4.0 * ATMOS_PI);
#elif ATMOS_MIE_PHASE_KIND == 3
    float x = clamp(nu, -1.0, 1.0);
    for (int i = 0; i < ATMOS_MIE_PHASE_TABLE_COUNT - 1; ++i) {
        float a = atmos_MiePhaseTableMu[i + 1];
        if (x >= a) {
            float b = atmos_MiePhaseTableMu[i];
            float f = (b - x) / (b - a);
            return mix(atmos_MiePhaseTableValue[i], atmos_MiePhaseTableValue[i + 1], f);
        }
    }
    return atmos_MiePhaseTableValue[ATMOS_MIE_PHASE_TABLE_COUNT - 1];
#elif defined(ATMOS_MIE_PHASE_WEIGHT2)
    float w = ATMOS_MIE_PHASE_WEIGHT2;
    return (1.0 - w) * atmos_MieLobe(ATMOS_MIE_PHASE_G, nu) + w * atmos_MieLobe(ATMOS_MIE_PHASE_G2, nu);
#else
    return atmos_MieLobe(ATMOS_MIE_PHASE_G, nu);
#endif
}
// DistanceToTopAtmosphereBoundary (geometry.h; Bruneton's 2017 implementation notes "Distance to the top
// atmosphere boundary"): discriminant r^2 (mu^2 - 1) + top^2.
float atmos_DistanceToTop(float r, float mu) {
    float disc = (ATMOS_TOP_RADIUS - r) * (ATMOS_TOP_RADIUS + r) + (r * mu) * (r * mu);
    return max(-r * mu + atmos_SafeSqrt(disc), 0.0);
}
// IntersectSphere (geometry.h): the stable roots t0 <= t1 of |o + t d| = radius.
bool atmos_IntersectSphere(vec3 o, vec3 d, float radius, out float t0, out float t1) {
    float b = dot(o, d);
    float r = length(o);
    float c = (r - radius) * (r + radius);
    float disc = b * b - c;
    t0 = 0.0;
    t1 = 0.0;
    if (disc < 0.0) return false;
    float s = sqrt(disc);
    float q = -(b + (b >= 0.0 ? s : -s));
    float tb = q != 0.0 ? c / q : -b;
    t0 = min(q, tb);
    t1 = max(q, tb);
    return true;
}
// ClipToAtmosphere (geometry.h): the part of the ray inside the shell and
// whether the ground ends it. Returns false when the ray misses the atmosphere
// (and for a camera on the ground looking down: hits_ground, no segment).
bool atmos_ClipToAtmosphere(vec3 camera, vec3 dir, out float t_start, out float t_end,
                            out bool hits_ground) {
    float top0, top1;
    t_start = 0.0;
    t_end = 0.0;
    hits_ground = false;
    if (!atmos_IntersectSphere(camera, dir, ATMOS_TOP_RADIUS, top0, top1) || top1 <= 0.0) {
        return false;
    }
    t_start = max(top0, 0.0);
    t_end = top1;
    if (length(camera) <= ATMOS_BOTTOM_RADIUS) {
        if (dot(camera, dir) < 0.0) {
            hits_ground = true;
            t_end = 0.0;
            return false;
        }
    } else {
        float g0, g1;
        if (atmos_IntersectSphere(camera, dir, ATMOS_BOTTOM_RADIUS, g0, g1) && g0 > 0.0 &&
            g0 < t_end) {
            hits_ground = true;
            t_end = g0;
        }
    }
    return t_end > t_start;
}
// BeginRay (physics/ray.h): resets a model's outputs (no light, T = 1) and
// clips the ray to the atmosphere (ClipToAtmosphere's result).
bool atmos_BeginRay(vec3 camera, vec3 dir, out vec3 sky, out vec3 ground,
                    out vec3 transmittance, out bool hits_ground, out float t_start,
                    out float t_end) {
    sky = vec3(0.0);
    ground = vec3(0.0);
    transmittance = vec3(1.0);
    return atmos_ClipToAtmosphere(camera, dir, t_start, t_end, hits_ground);
}
// MaxComponent(ground_albedo) > 0: the evaluators shade the ground only then.
bool atmos_GroundReflects() {
    return max(ATMOS_GROUND_ALBEDO.r, max(ATMOS_GROUND_ALBEDO.g, ATMOS_GROUND_ALBEDO.b)) > 0.0;
}
// GetLayerDensity / GetProfileDensity (physics/density.h; Bruneton's 2017 implementation notes): a layer is
// vec4(exp_term, exp_scale, linear_term, constant_term); a zero exp_term has no
// exponential (0 * exp(large) would be NaN).
float atmos_LayerDensity(vec4 l, float altitude) {
    float e = l.x != 0.0 ? l.x * exp(l.y * altitude) : 0.0;
    return clamp(e + l.z * altitude + l.w, 0.0, 1.0);
}
float atmos_ProfileDensity(float width0, vec4 l0, vec4 l1, float altitude) {
    return altitude < width0 ? atmos_LayerDensity(l0, altitude) : atmos_LayerDensity(l1, altitude);
}
// GetDensities (physics/density.h): the Rayleigh, Mie and absorption densities
// at an altitude, as (x, y, z).
vec3 atmos_Densities(float altitude) {
    return vec3(atmos_ProfileDensity(ATMOS_RAYLEIGH_WIDTH0, ATMOS_RAYLEIGH_LAYER0,
                                     ATMOS_RAYLEIGH_LAYER1, altitude),
                atmos_ProfileDensity(ATMOS_MIE_WIDTH0, ATMOS_MIE_LAYER0, ATMOS_MIE_LAYER1,
                                     altitude),
                atmos_ProfileDensity(ATMOS_ABSORPTION_WIDTH0, ATMOS_ABSORPTION_LAYER0,
                                     ATMOS_ABSORPTION_LAYER1, altitude));
}
