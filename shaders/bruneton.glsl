// atmos shaders: the `bruneton` model's rendering functions over the tables of
// `atmos bake bruneton` (GLSL ES 3.00 and GLSL 3.30 core: no extensions).
//
// Written for atmos from the math of Bruneton 2017, "Precomputed
// atmospheric scattering: a new implementation" and our C++ code; every
// function names the C++ function in src/atmos/models/bruneton.h (struct
// BrunetonLut / BrunetonEvaluator) or src/atmos/physics/ it mirrors and the
// Bruneton's 2017 implementation notes section it implements. It is not Bruneton's published GLSL.
//
// Use: include, in this order,
//   1. the #version line and `precision highp float; precision highp sampler3D;`
//      (GLSL ES),
//   2. DIR/shaders/bruneton_constants.glsl (written by the bake: the
//      atmosphere's radii, Mie g, scattering coefficients, table sizes),
//   3. DIR/shaders/common.glsl (the shared math and geometry),
//   4. this file,
// then bind the tables (DIR/tables.f32 or .f16, offsets in DIR/bruneton.json
// "raw") as textures with LINEAR filtering and CLAMP_TO_EDGE wrapping:
//   atmos_transmittance_texture  2D  RGB  transmittance.exr
//   atmos_irradiance_texture     2D  RGB  irradiance.exr
//   atmos_scattering_texture     3D  RGB  scattering.exr (RGBA if combined Mie)
//   atmos_single_mie_texture     3D  RGB  single_mie_scattering.exr (separate Mie)
// Float32 tables need OES_texture_float_linear for LINEAR filtering in WebGL2;
// float16 tables filter everywhere.
//
// Units: metres, planet-centred positions (the planet's centre is the origin).
// Results are per unit solar irradiance, as in the C++ (multiply by the sun's
// irradiance at the top of the atmosphere; ATMOS_SOLAR_IRRADIANCE is the
// atmosphere's).
//
// Precision: the C++ computes geometry in double; here float. The quadratic
// forms are rearranged as the C++ (IntersectSphere, RayIntersectsGround) to
// avoid the cancellation of r^2 - R^2 at 6.4e6 m.

uniform highp sampler2D atmos_transmittance_texture;
uniform highp sampler2D atmos_irradiance_texture;
uniform highp sampler3D atmos_scattering_texture;
#if !ATMOS_COMBINED_MIE
uniform highp sampler3D atmos_single_mie_texture;
#endif

// ---- geometry (BrunetonLut; the shared helpers are in common.glsl) ----

// BrunetonLut::ClampRadius (Bruneton's 2017 implementation notes ClampRadius).
float atmos_ClampRadius(float r) { return clamp(r, ATMOS_BOTTOM_RADIUS, ATMOS_TOP_RADIUS); }
// BrunetonLut::HorizonH: distance to the top for a horizontal ray on the ground.
float atmos_HorizonH() {
    return sqrt((ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS) * (ATMOS_TOP_RADIUS + ATMOS_BOTTOM_RADIUS));
}
// rho = sqrt(r^2 - bottom^2), as (r - bottom)(r + bottom).
float atmos_Rho(float r) {
    return atmos_SafeSqrt((r - ATMOS_BOTTOM_RADIUS) * (r + ATMOS_BOTTOM_RADIUS));
}
// DistanceToBottomAtmosphereBoundary (Bruneton's 2017 implementation notes, same section).
float atmos_DistanceToBottom(float r, float mu) {
    float disc = (ATMOS_BOTTOM_RADIUS - r) * (ATMOS_BOTTOM_RADIUS + r) + (r * mu) * (r * mu);
    return max(-r * mu - atmos_SafeSqrt(disc), 0.0);
}
// SmoothStep (BrunetonLut::SmoothStep).
float atmos_SmoothStep(float e0, float e1, float x) {
    float t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// ---- transmittance (Bruneton's 2017 implementation notes "Transmittance": precomputation and lookup) ----

// BrunetonLut::TransmittanceUvFromRMu (Bruneton's 2017 implementation notes GetTransmittanceTextureUvFromRMu).
vec2 atmos_TransmittanceUv(float r, float mu) {
    float H = atmos_HorizonH();
    float rho = atmos_Rho(r);
    float d = atmos_DistanceToTop(r, mu);
    float d_min = ATMOS_TOP_RADIUS - r;
    float d_max = rho + H;
    float x_mu = (d - d_min) / (d_max - d_min);
    float x_r = rho / H;
    return vec2(atmos_TextureCoord(x_mu, float(ATMOS_TRANSMITTANCE_WIDTH)),
                atmos_TextureCoord(x_r, float(ATMOS_TRANSMITTANCE_HEIGHT)));
}
// BrunetonLut::TransmittanceToTop (Bruneton's 2017 implementation notes GetTransmittanceToTopAtmosphereBoundary).
vec3 atmos_TransmittanceToTop(float r, float mu) {
    vec2 uv = atmos_TransmittanceUv(atmos_ClampRadius(r), atmos_ClampCosine(mu));
    return texture(atmos_transmittance_texture, uv).rgb;
}
// BrunetonLut::SafeRatio: min(t, 1), 0 where the ratio is not finite.
vec3 atmos_SafeRatio(vec3 num, vec3 den) {
    vec3 t;
    for (int i = 0; i < 3; ++i) t[i] = den[i] > 0.0 ? clamp(num[i] / den[i], 0.0, 1.0) : 0.0;
    return t;
}
// BrunetonLut::Transmittance (Bruneton's 2017 implementation notes GetTransmittance): between (r, mu) and
// the point at distance d; the caller says whether the ray hits the ground.
vec3 atmos_Transmittance(float r, float mu, float d, bool ray_r_mu_intersects_ground) {
    float r_d = atmos_ClampRadius(sqrt(d * d + 2.0 * r * mu * d + r * r));
    float mu_d = atmos_ClampCosine((r * mu + d) / r_d);
    if (ray_r_mu_intersects_ground) {
        return atmos_SafeRatio(atmos_TransmittanceToTop(r_d, -mu_d),
                               atmos_TransmittanceToTop(r, -mu));
    }
    return atmos_SafeRatio(atmos_TransmittanceToTop(r, mu), atmos_TransmittanceToTop(r_d, mu_d));
}
// BrunetonLut::TransmittanceToSun (Bruneton's 2017 implementation notes GetTransmittanceToSun): the visible
// fraction of the sun's disc above the horizon as a smoothstep.
vec3 atmos_TransmittanceToSun(float r, float mu_s) {
    float sin_theta_h = ATMOS_BOTTOM_RADIUS / r;
    float cos_theta_h = -atmos_SafeSqrt(1.0 - sin_theta_h * sin_theta_h);
    float a = sin_theta_h * ATMOS_SUN_ANGULAR_RADIUS;
    float f = atmos_SmoothStep(-a, a, mu_s - cos_theta_h);
    if (f <= 0.0) return vec3(0.0);
    return atmos_TransmittanceToTop(r, mu_s) * f;
}

// ---- scattering (Bruneton's 2017 implementation notes "Single scattering": the 4D texture and its lookup) ----

// BrunetonLut::ScatteringUvwz (Bruneton's 2017 implementation notes GetScatteringTextureUvwzFromRMuMuSNu):
// (u_nu, u_mu_s, u_mu, u_r); mu split at the horizon.
vec4 atmos_ScatteringUvwz(float r, float mu, float mu_s, float nu,
                          bool ray_r_mu_intersects_ground) {
    float H = atmos_HorizonH();
    float rho = atmos_Rho(r);
    float u_r = atmos_TextureCoord(rho / H, float(ATMOS_SCATTERING_R));
    float r_mu = r * mu;
    float disc = r_mu * r_mu - (r - ATMOS_BOTTOM_RADIUS) * (r + ATMOS_BOTTOM_RADIUS);
    float half_mu = float(ATMOS_SCATTERING_MU / 2);
    float u_mu;
    if (ray_r_mu_intersects_ground) {
        float d = -r_mu - atmos_SafeSqrt(disc);
        float d_min = r - ATMOS_BOTTOM_RADIUS;
        float d_max = rho;
        float x = d_max == d_min ? 0.0 : (d - d_min) / (d_max - d_min);
        u_mu = 0.5 - 0.5 * atmos_TextureCoord(x, half_mu);
    } else {
        float d = -r_mu + atmos_SafeSqrt(disc + H * H);
        float d_min = ATMOS_TOP_RADIUS - r;
        float d_max = rho + H;
        u_mu = 0.5 + 0.5 * atmos_TextureCoord((d - d_min) / (d_max - d_min), half_mu);
    }
    // BrunetonLut::ScatteringUMuS.
    float d = atmos_DistanceToTop(ATMOS_BOTTOM_RADIUS, mu_s);
    float d_min = ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS;
    float d_max = H;
    float a = (d - d_min) / (d_max - d_min);
    float D = atmos_DistanceToTop(ATMOS_BOTTOM_RADIUS, ATMOS_MU_S_MIN);
    float A = (D - d_min) / (d_max - d_min);
    float u_mu_s =
        atmos_TextureCoord(max(1.0 - a / A, 0.0) / (1.0 + a), float(ATMOS_SCATTERING_MU_S));
    float u_nu = (nu + 1.0) / 2.0;
    return vec4(u_nu, u_mu_s, u_mu, u_r);
}
// BrunetonLut::Lookup4D (Bruneton's 2017 implementation notes GetScattering): the 4D table as NU slices of
// MU_S texels side by side in x; two trilinear lookups blended along nu.
vec4 atmos_Lookup4D(highp sampler3D table, vec4 uvwz) {
    float nu_size = float(ATMOS_SCATTERING_NU);
    float tex_coord_x = uvwz.x * (nu_size - 1.0);
    float tex_x = floor(tex_coord_x);
    float lerp = tex_coord_x - tex_x;
    vec3 uvw0 = vec3((tex_x + uvwz.y) / nu_size, uvwz.z, uvwz.w);
    vec3 uvw1 = vec3((tex_x + 1.0 + uvwz.y) / nu_size, uvwz.z, uvwz.w);
    return texture(table, uvw0) * (1.0 - lerp) + texture(table, uvw1) * lerp;
}
// BrunetonLut::ExtrapolatedSingleMie (Bruneton's 2017 implementation notes GetExtrapolatedSingleMieScattering).
vec3 atmos_ExtrapolatedSingleMie(vec4 s) {
    if (s.r <= 0.0) return vec3(0.0);
    vec3 ratio = ATMOS_MIE_SCATTERING / ATMOS_RAYLEIGH_SCATTERING *
                 (ATMOS_RAYLEIGH_SCATTERING.r / ATMOS_MIE_SCATTERING.r);
    return s.rgb * (s.a / s.r) * ratio;
}
// BrunetonLut::CombinedScattering (Bruneton's 2017 implementation notes GetCombinedScattering): Rayleigh +
// multiple scattering (returned) and the single Mie scattering, no phase.
vec3 atmos_CombinedScattering(float r, float mu, float mu_s, float nu,
                              bool ray_r_mu_intersects_ground, out vec3 single_mie) {
    vec4 uvwz = atmos_ScatteringUvwz(atmos_ClampRadius(r), atmos_ClampCosine(mu),
                                     atmos_ClampCosine(mu_s), atmos_ClampCosine(nu),
                                     ray_r_mu_intersects_ground);
    vec4 s = atmos_Lookup4D(atmos_scattering_texture, uvwz);
#if ATMOS_COMBINED_MIE
    single_mie = atmos_ExtrapolatedSingleMie(s);
#else
    single_mie = atmos_Lookup4D(atmos_single_mie_texture, uvwz).rgb;
#endif
    return s.rgb;
}

// ---- irradiance (Bruneton's 2017 implementation notes "Ground irradiance") ----

// BrunetonLut::IrradianceUvFromRMuS + GetIrradiance (Bruneton's 2017 implementation notes GetIrradiance).
vec3 atmos_GetIrradiance(float r, float mu_s) {
    float x_r = (r - ATMOS_BOTTOM_RADIUS) / (ATMOS_TOP_RADIUS - ATMOS_BOTTOM_RADIUS);
    float x_mu_s = mu_s * 0.5 + 0.5;
    vec2 uv = vec2(atmos_TextureCoord(x_mu_s, float(ATMOS_IRRADIANCE_WIDTH)),
                   atmos_TextureCoord(x_r, float(ATMOS_IRRADIANCE_HEIGHT)));
    return texture(atmos_irradiance_texture, uv).rgb;
}

// ---- rendering (Bruneton's 2017 implementation notes "Rendering") ----

// BrunetonLut::SkyRadiance (Bruneton's 2017 implementation notes GetSkyRadiance): radiance of the sky along
// view_ray (unit) from camera, per unit solar irradiance; transmittance to
// space in `transmittance`. A camera in space is moved to the top of the
// atmosphere; a ray that misses it gets L = 0, T = 1. `ray_hits_ground`: the
// caller's robust answer (atmos_ClipToAtmosphere). shadow_length: light shafts
// (0: none).
vec3 atmos_SkyRadiance(vec3 camera, vec3 view_ray, float shadow_length, vec3 sun_direction,
                       bool ray_hits_ground, out vec3 transmittance) {
    float r = length(camera);
    float rmu = dot(camera, view_ray);
    float disc = rmu * rmu - (r - ATMOS_TOP_RADIUS) * (r + ATMOS_TOP_RADIUS);
    float to_top = disc >= 0.0 ? -rmu - sqrt(disc) : -1.0;
    if (r > ATMOS_TOP_RADIUS) {
        if (to_top > 0.0) {
            camera = camera + view_ray * to_top;
            r = ATMOS_TOP_RADIUS;
            rmu += to_top;
        } else {
            transmittance = vec3(1.0);
            return vec3(0.0);
        }
    }
    r = atmos_ClampRadius(r);
    float mu = atmos_ClampCosine(rmu / r);
    float mu_s = atmos_ClampCosine(dot(camera, sun_direction) / r);
    float nu = atmos_ClampCosine(dot(view_ray, sun_direction));
    transmittance = ray_hits_ground ? vec3(0.0) : atmos_TransmittanceToTop(r, mu);
    vec3 single_mie;
    vec3 scattering;
    if (shadow_length == 0.0) {
        scattering = atmos_CombinedScattering(r, mu, mu_s, nu, ray_hits_ground, single_mie);
    } else {
        // Light shafts (Bruneton's 2017 implementation notes; Bruneton & Neyret 2008 Eq. 18): omit the first l metres.
        float d = shadow_length;
        float r_p = atmos_ClampRadius(sqrt(d * d + 2.0 * r * mu * d + r * r));
        float mu_p = (r * mu + d) / r_p;
        float mu_s_p = (r * mu_s + d * nu) / r_p;
        scattering = atmos_CombinedScattering(r_p, mu_p, mu_s_p, nu, ray_hits_ground, single_mie);
        vec3 shadow_t = atmos_Transmittance(r, mu, shadow_length, ray_hits_ground);
        scattering *= shadow_t;
        single_mie *= shadow_t;
    }
    return scattering * atmos_RayleighPhase(nu) + single_mie * atmos_MiePhase(nu);
}

// BrunetonLut::SegmentSingleMie (issue 15): single Mie scattering without the
// phase function between the camera at (r, mu, mu_s, nu) and the point at
// distance d, by the midpoint rule in ATMOS_LOW_SUN_MIE_STEPS samples; the view
// transmittance from the extinction accumulated along the segment, the sun's
// from the table.
vec3 atmos_SegmentSingleMie(float r, float mu, float mu_s, float nu, float d) {
    int n = ATMOS_LOW_SUN_MIE_STEPS;
    float dt = d / float(n);
    vec3 tau = vec3(0.0);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < n; ++i) {
        float t = (float(i) + 0.5) * dt;
        float r_t = atmos_ClampRadius(sqrt(t * t + 2.0 * r * mu * t + r * r));
        float alt = r_t - ATMOS_BOTTOM_RADIUS;
        vec3 d = atmos_Densities(alt);
        float d_r = d.x, d_m = d.y, d_a = d.z;
        vec3 ext = ATMOS_RAYLEIGH_SCATTERING * d_r + ATMOS_MIE_EXTINCTION * d_m +
                   ATMOS_ABSORPTION_EXTINCTION * d_a;
        vec3 tau_mid = tau + ext * (0.5 * dt);
        tau += ext * dt;
        vec3 ts = atmos_TransmittanceToSun(r_t, atmos_ClampCosine((r * mu_s + t * nu) / r_t));
        sum += ts * exp(-tau_mid) * (d_m * dt);
    }
    return sum * ATMOS_MIE_SCATTERING;
}

// BrunetonLut::SkyRadianceToPoint (Bruneton's 2017 implementation notes GetSkyRadianceToPoint): the
// scattering between camera and point (aerial perspective) as the difference
// of two lookups; the transmittance between them in `transmittance`.
vec3 atmos_SkyRadianceToPoint(vec3 camera, vec3 point, float shadow_length, vec3 sun_direction,
                              bool ray_hits_ground, out vec3 transmittance) {
    vec3 view_ray = normalize(point - camera);
    float r = length(camera);
    float rmu = dot(camera, view_ray);
    float disc = rmu * rmu - (r - ATMOS_TOP_RADIUS) * (r + ATMOS_TOP_RADIUS);
    float to_top = disc >= 0.0 ? -rmu - sqrt(disc) : -1.0;
    if (r > ATMOS_TOP_RADIUS && to_top > 0.0) {
        camera = camera + view_ray * to_top;
        r = ATMOS_TOP_RADIUS;
        rmu += to_top;
    }
    r = atmos_ClampRadius(r);
    float mu = atmos_ClampCosine(rmu / r);
    float mu_s = atmos_ClampCosine(dot(camera, sun_direction) / r);
    float nu = atmos_ClampCosine(dot(view_ray, sun_direction));
    float d = length(point - camera);
    transmittance = atmos_Transmittance(r, mu, d, ray_hits_ground);
    vec3 single_mie;
    vec3 scattering = atmos_CombinedScattering(r, mu, mu_s, nu, ray_hits_ground, single_mie);
    // The second lookup at the point, or shadow_length before it (Eq. 17).
    d = max(d - shadow_length, 0.0);
    float r_p = atmos_ClampRadius(sqrt(d * d + 2.0 * r * mu * d + r * r));
    float mu_p = (r * mu + d) / r_p;
    float mu_s_p = (r * mu_s + d * nu) / r_p;
    vec3 single_mie_p;
    vec3 scattering_p =
        atmos_CombinedScattering(r_p, mu_p, mu_s_p, nu, ray_hits_ground, single_mie_p);
    vec3 shadow_t = transmittance;
    if (shadow_length > 0.0) shadow_t = atmos_Transmittance(r, mu, d, ray_hits_ground);
    scattering = scattering - shadow_t * scattering_p;
    single_mie = single_mie - shadow_t * single_mie_p;
#if ATMOS_COMBINED_MIE
    single_mie = atmos_ExtrapolatedSingleMie(vec4(scattering, single_mie.r));
#endif
    // Bruneton's 2017 implementation notes fades single Mie out below mu_s = 0.01 (its hack against the
    // lookups' difference artefacts); by default (ATMOS_LOW_SUN_MIE 0) the
    // faded part is the single Mie integral along the segment (issue 15).
    float fade = atmos_SmoothStep(0.0, 0.01, mu_s);
#if ATMOS_LOW_SUN_MIE != 2
    if (fade < 1.0) {
        single_mie *= fade;
#if ATMOS_LOW_SUN_MIE == 0
        single_mie += atmos_SegmentSingleMie(r, mu, mu_s, nu, d) * (1.0 - fade);
#endif
    }
#endif
    return max(scattering, vec3(0.0)) * atmos_RayleighPhase(nu) +
           max(single_mie, vec3(0.0)) * atmos_MiePhase(nu);
}

// BrunetonLut::SunAndSkyIrradiance (Bruneton's 2017 implementation notes GetSunAndSkyIrradiance): the sun's
// irradiance at `point` on a surface with `normal` (returned) and the sky's
// (`sky_irradiance`: the horizontal-surface table times (1 + n.up) / 2).
vec3 atmos_SunAndSkyIrradiance(vec3 point, vec3 normal, vec3 sun_direction,
                               out vec3 sky_irradiance) {
    float len = length(point);
    float r = atmos_ClampRadius(len);
    float mu_s = atmos_ClampCosine(dot(point, sun_direction) / len);
    sky_irradiance = atmos_GetIrradiance(r, mu_s) * ((1.0 + dot(normal, point) / len) * 0.5);
    return atmos_TransmittanceToSun(r, mu_s) * max(dot(normal, sun_direction), 0.0);
}

// BrunetonEvaluator::Evaluate: what `atmos render` computes per pixel, per unit
// solar irradiance: the sky in-scattered along the ray (to space, or to the
// ground), the lit Lambertian ground attenuated to the camera, and the
// transmittance of the ray's segment in the atmosphere.
void atmos_Evaluate(vec3 camera, vec3 dir, vec3 sun, out vec3 sky, out vec3 ground,
                    out vec3 transmittance, out bool hits_ground) {
    float t_start, t_end;
    bool inside =
        atmos_BeginRay(camera, dir, sky, ground, transmittance, hits_ground, t_start, t_end);
    if (!inside && !hits_ground) return;
    if (!hits_ground) {
        sky = atmos_SkyRadiance(camera, dir, 0.0, sun, false, transmittance);
        return;
    }
    // A camera on the ground looking down sees the ground at its feet.
    vec3 ground_point = inside ? camera + dir * t_end : camera;
    if (inside) {
        sky = atmos_SkyRadianceToPoint(camera, ground_point, 0.0, sun, true, transmittance);
    }
    if (atmos_GroundReflects()) {
        vec3 normal = normalize(ground_point);
        vec3 sky_irradiance;
        vec3 sun_irradiance = atmos_SunAndSkyIrradiance(ground_point, normal, sun, sky_irradiance);
        ground = ATMOS_GROUND_ALBEDO * (1.0 / ATMOS_PI) * (sun_irradiance + sky_irradiance) *
                 transmittance;
    }
}
