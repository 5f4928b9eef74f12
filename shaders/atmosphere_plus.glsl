// atmos shaders: the `atmosphere-plus` model (J. Boody, "Atmosphere Plus"
// notes, Boody's Atmosphere Plus notes) over the tables of `atmos bake atmosphere-plus` (GLSL ES
// 3.00 and GLSL 3.30 core: no extensions).
//
// Written for atmos from Boody's Atmosphere Plus notes' math (sections 1.7, 2.3, 2.4) and our C++
// code; every function names the C++ function in
// src/atmos/models/atmosphere_plus.h (AtmospherePlusEvaluator, the table
// lookups) or atmosphere_plus_mapping.h (AplusMapping: the four
// parameterizations) it mirrors and Boody's Atmosphere Plus notes section it implements.
//
// Use: include, in this order,
//   1. the #version line and `precision highp float; precision highp sampler3D;`
//      (GLSL ES),
//   2. DIR/shaders/atmosphere_plus_constants.glsl (written by the bake: radii,
//      Mie g, the mapping's kind and powers, table sizes, the Rayleigh phase),
//   3. DIR/shaders/common.glsl (the shared math and geometry),
//   4. this file,
// then bind the tables (DIR/tables.f32 or .f16, offsets in
// DIR/atmosphere-plus.json "raw") with LINEAR filtering and CLAMP_TO_EDGE:
//   atmos_scattering_texture     3D RGBA W x H x D  scattering.exr
//                                x: altitude (u), y: view zenith (v), z: sun zenith (w);
//                                RGB: factored Rayleigh intensity, A: factored Mie
//   atmos_transmittance_texture  2D RGB  W x H      transmittance.exr
//                                x: altitude (u), y: view zenith (v)
// Float32 tables need OES_texture_float_linear for LINEAR filtering in WebGL2;
// float16 tables filter everywhere.
//
// Units: metres, planet-centred positions. Results per unit solar irradiance
// (Boody's Atmosphere Plus notes 2.3 factors I_I out: multiply by ATMOS_SOLAR_IRRADIANCE, the
// atmosphere's, times the scene's).
//
// Tables: texel i holds the value at i / (size - 1) (Boody's Atmosphere Plus notes 2.4), i.e. the
// unit coordinate t sits at atmos_TextureCoord(t, size). The altitude axis is
// not filtered by the sampler: as the C++ (AplusSampleTable) the lookup blends
// the two altitude rows around h, each sampled (bilinear in v, w) at the v of
// its own altitude, because the horizon-centric v depends on h.

uniform highp sampler3D atmos_scattering_texture;
uniform highp sampler2D atmos_transmittance_texture;

// ---- the parameterizations (Boody's Atmosphere Plus notes section 2.4; atmosphere_plus_mapping.h) ----

// AplusPow: x^p for x >= 0, exact for the seed's powers 1, 2, 3.
float atmos_AplusPow(float x, float p) {
    return p == 1.0 ? x : p == 2.0 ? x * x : p == 3.0 ? x * x * x : pow(x, p);
}
// AplusRoot: x^(1/p) for x >= 0 (Boody's Atmosphere Plus notes 2.4.2-2.4.3).
float atmos_AplusRoot(float x, float p) {
    return p == 1.0 ? x : p == 2.0 ? sqrt(x) : x > 0.0 ? pow(x, 1.0 / p) : 0.0;
}
// AplusSignedRoot: sign(c) |c|^(1/p) (Boody's Atmosphere Plus notes 2.4.3).
float atmos_AplusSignedRoot(float c, float p) {
    float a = atmos_AplusRoot(abs(c), p);
    return c < 0.0 ? -a : a;
}
// AplusMapping::HorizonCosine (Boody's Atmosphere Plus notes 2.4.4): the cosine of the horizon's
// view-zenith angle at altitude h. Geometric: -sqrt(1 - (R/(R+h))^2), written
// -sqrt(h (2R + h)) / (R + h) so that float keeps it for small h; the seed's
// -1 + R/(R+h) as -h / (R + h).
float atmos_AplusHorizonCosine(float h) {
    h = max(h, 0.0);
    float r = ATMOS_BOTTOM_RADIUS + h;
#if ATMOS_APLUS_SEED_HORIZON
    return -h / r;
#else
    return -sqrt(h * (2.0 * ATMOS_BOTTOM_RADIUS + h)) / r;
#endif
}
// AplusMapping::U (Boody's Atmosphere Plus notes 2.4.1-2.4.4): u = (h / H_a)^(1/p_u).
float atmos_AplusU(float h) {
    return atmos_AplusRoot(clamp(h / (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS), 0.0, 1.0),
                           ATMOS_APLUS_POWER_U);
}
// AplusMapping::H: the inverse, h = u^p_u H_a.
float atmos_AplusH(float u) {
    return atmos_AplusPow(clamp(u, 0.0, 1.0), ATMOS_APLUS_POWER_U) *
           (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
}
// AplusMapping::V: the view-zenith coordinate. Power maps (2.4.1-2.4.3):
// (sign(mu)|mu|^(1/p_v) + 1) / 2; horizon-centric (2.4.4): split at the
// horizon cosine c_h, the sky above s u(h), the surface below.
float atmos_AplusV(float h, float mu) {
    mu = clamp(mu, -1.0, 1.0);
#if ATMOS_APLUS_HORIZON_MAPPING
    float c_h = atmos_AplusHorizonCosine(h);
    float su = ATMOS_APLUS_SURFACE_RATIO * atmos_AplusU(h);
    if (mu >= c_h) {
        float x = clamp((mu - c_h) / (1.0 - c_h), 0.0, 1.0);
        return (1.0 - su) * atmos_AplusRoot(x, ATMOS_APLUS_P_A) + su;
    }
    float x = clamp((mu - c_h) / (-1.0 - c_h), 0.0, 1.0);
    return su * (1.0 - atmos_AplusRoot(x, ATMOS_APLUS_P_S));
#else
    return 0.5 * (atmos_AplusSignedRoot(mu, ATMOS_APLUS_POWER_V) + 1.0);
#endif
}
// AplusMapping::W: the sun-zenith coordinate (2.4.1-2.4.3; the horizon-centric
// mapping uses the power map with p_w, the seed leaves w open).
float atmos_AplusW(float mu_s) {
    return 0.5 * (atmos_AplusSignedRoot(clamp(mu_s, -1.0, 1.0), ATMOS_APLUS_POWER_W) + 1.0);
}

// ---- table lookups (AplusSampleTable) ----

// TableView::Split: a texture coordinate -> the lower texel index and the
// fraction toward the next one, clamped to the edge texels.
void atmos_AplusSplit(float u, int size, out int i0, out float f) {
    float x = clamp(u * float(size) - 0.5, 0.0, float(size - 1));
    i0 = min(int(x), max(size - 2, 0));
    f = size > 1 ? x - float(i0) : 0.0;
}
// The altitude of table row x (AplusSampleTable's h_row: texel x holds
// u = x / (width - 1)).
float atmos_AplusRowAltitude(int x, int width) {
    return atmos_AplusH(width > 1 ? float(x) / float(width - 1) : 0.0);
}
// AplusSampleTable: the scattering table (RGBA) or, with `transmittance`, the
// transmittance table (RGB, A = 0) at (h, mu) and the table's w coordinate:
// linear between the two altitude rows around h, each row bilinear in (v, w)
// at the v of its own altitude. A ray below the horizon at the ground row has
// no length: `ground_row` there (0 for scattering, 1 for transmittance).
// textureLod: the fetches sit in non-uniform control flow (no derivatives).
vec4 atmos_AplusSampleTable(bool transmittance, float h, float mu, float w, vec4 ground_row) {
    int width = transmittance ? ATMOS_TRANSMITTANCE_WIDTH : ATMOS_SCATTERING_WIDTH;
    float height = float(transmittance ? ATMOS_TRANSMITTANCE_HEIGHT : ATMOS_SCATTERING_HEIGHT);
    int x0;
    float fx;
    atmos_AplusSplit(atmos_TextureCoord(atmos_AplusU(h), float(width)), width, x0, fx);
    vec4 result = vec4(0.0);
    for (int k = 0; k < 2; ++k) {
        float weight = k == 0 ? 1.0 - fx : fx;
        if (weight == 0.0) continue;
        int x = min(x0 + k, width - 1);
        float h_row = atmos_AplusRowAltitude(x, width);
        if (h_row <= 0.0 && mu < 0.0) {
            result += ground_row * weight;
            continue;
        }
        vec3 uvw = vec3((float(x) + 0.5) / float(width),
                        atmos_TextureCoord(atmos_AplusV(h_row, mu), height), w);
        vec4 texel = transmittance
                         ? vec4(textureLod(atmos_transmittance_texture, uvw.xy, 0.0).rgb, 0.0)
                         : textureLod(atmos_scattering_texture, uvw, 0.0);
        result += texel * weight;
    }
    return result;
}
// AplusSample: the factored intensity (Rayleigh RGB, Mie A) at (h, mu, mu_s).
vec4 atmos_AplusScattering(float h, float mu, float mu_s) {
    float w = atmos_TextureCoord(atmos_AplusW(mu_s), float(ATMOS_SCATTERING_DEPTH));
    return atmos_AplusSampleTable(false, h, mu, w, vec4(0.0));
}
// AplusSampleTransmittance: the transmittance of the view segment from
// altitude h along mu (Boody's Atmosphere Plus notes 1.10; 1 below the horizon at the ground row).
vec3 atmos_AplusTransmittance(float h, float mu) {
    return atmos_AplusSampleTable(true, h, mu, 0.5, vec4(1.0)).rgb;
}

// ---- rendering (Boody's Atmosphere Plus notes sections 1.7, 2.3, 2.4) ----

// AplusRayleighPhase / AplusModifiedRayleighPhase (Boody's Atmosphere Plus notes 1.7, normalised
// to 4 pi; ATMOS_APLUS_MODIFIED_RAYLEIGH: 0.8 (1.4 + 0.5 nu^2)).
float atmos_AplusRayleighPhase(float nu) {
#if ATMOS_APLUS_MODIFIED_RAYLEIGH
    return 0.8 * (1.4 + 0.5 * nu * nu);
#else
    return 0.75 * (1.0 + nu * nu);
#endif
}
// AplusMiePhase (Boody's Atmosphere Plus notes 1.7): 4 pi x the Cornette-Shanks phase function.
float atmos_AplusMiePhase(float nu) { return 4.0 * ATMOS_PI * atmos_MiePhase(nu); }

// The Lambertian ground at point g lit by the sun through the transmittance
// from the ground (the ground terms of AtmospherePlusEvaluator::Evaluate).
vec3 atmos_AplusGround(vec3 g, vec3 sun) {
    float cos_sun = dot(normalize(g), sun);
    if (cos_sun <= 0.0) return vec3(0.0);
    return ATMOS_GROUND_ALBEDO * (cos_sun / ATMOS_PI) * atmos_AplusTransmittance(0.0, cos_sun);
}

// AtmospherePlusEvaluator::Evaluate: what `atmos render` computes per pixel,
// per unit solar irradiance. P_0 is the camera, or where the ray enters the
// atmosphere (Boody's Atmosphere Plus notes 2.4); sky = F_R(nu) I_R + F_M(nu) I_M with nu =
// dot(L, -V) = dot(sun, V) (2.3); the transmittance of the view segment; the
// lit ground attenuated to the camera (a camera on the ground looking down
// sees the ground at its feet through no air).
void atmos_Evaluate(vec3 camera, vec3 dir, vec3 sun, out vec3 sky, out vec3 ground,
                    out vec3 transmittance, out bool hits_ground) {
    float t_start, t_end;
    bool inside =
        atmos_BeginRay(camera, dir, sky, ground, transmittance, hits_ground, t_start, t_end);
    bool lit_ground = atmos_GroundReflects();
    if (!inside) {
        if (hits_ground && lit_ground) ground = atmos_AplusGround(camera, sun);
        return;
    }
    vec3 p0 = camera + dir * t_start;
    float r = length(p0);
    float h = clamp(r - ATMOS_BOTTOM_RADIUS, 0.0, ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
    float mu = atmos_ClampCosine(dot(p0, dir) / r);
    float mu_s = atmos_ClampCosine(dot(p0, sun) / r);
    float nu = atmos_ClampCosine(dot(dir, sun));
    vec4 s = atmos_AplusScattering(h, mu, mu_s);
    sky = max(s.rgb * atmos_AplusRayleighPhase(nu) + vec3(s.a * atmos_AplusMiePhase(nu)),
              vec3(0.0));
    transmittance = atmos_AplusTransmittance(h, mu);
    if (hits_ground && lit_ground) {
        ground = atmos_AplusGround(camera + dir * t_end, sun) * transmittance;
    }
}
