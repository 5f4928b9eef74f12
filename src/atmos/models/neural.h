// atmos model `neural`: the thesis's fitted neural-network sky.
//
// Source: Leenman's 2025 thesis section 9.6 (networks, 9.6.3 implementation as an
// atmosphere: Eq. 43 and 44), 11.2.8, 11.3.2; segment handling after Bruneton &
// Neyret 2008.
//
// Implements: a transmittance network T(h, mu) (2 -> 4 -> 3, sigmoid; the
// transmittance from altitude h along mu to the top of the atmosphere) and a
// scattering network S(h, mu, mu_s, nu) (4 -> 8 -> 8 -> 3, sigmoid hidden, exp(-x)
// output; the sky radiance per unit solar irradiance along the ray to its end)
// fitted by `atmos fit` (models/neural_train.h) to a reference model. Per ray:
//  - a camera outside the atmosphere is moved to where the ray enters it
//    (Leenman's 2025 thesis section 9.6.3); a ray that misses the atmosphere sees nothing;
//  - a ray that leaves through the top: T = T(h_v, mu_v), S = S(h_v, mu_v, ...);
//  - a ray that meets the ground at g is reversed for the transmittance
//    (section 9.6.3): T = T(g, -v) / T(camera, -v) (Eq. 43), and
//    S = S(camera, v) - S(g, v) T (Eq. 44). The scattering network is fitted
//    to the reference's radiance of the ray up to its end (ground or top, the
//    DESIGN.md sample contract), so S(g, v) from the ground looking down is
//    near 0 and Eq. 44 mostly removes the fit's residual there; it becomes the
//    full aerial-perspective formula for segments ending in the air.
//  Ground: albedo / pi max(0, n.s) T_sun(g) T (direct sun only).
//
// Output: radiance per unit solar irradiance (1/sr) and the segment's
// transmittance, as fitted; multiple scattering as far as the reference had it
// (bruneton, default: 4 orders).
// Valid: for the atmosphere the weights were fitted to (checked at Prepare),
// any camera, sun down to the fit's lowest mu_s (-0.35; lower: no sky).
// Deviations: the ground gets no sky light; weights are per atmosphere.
// Options: `network` thesis (the sizes above) | large (two hidden layers of 32,
// the `horizon` input encoding, models/neural_net.h); `weights` FILE overrides
// both (any encoding the file names: thesis, extended, horizon).
#pragma once

#include <string>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "models/neural_net.h"
#include "physics/geometry.h"

namespace atmos {

// Lowest sun cosine in the training data (Leenman's 2025 thesis section 9.1 limits the sun to
// 0..100 degrees; we go a little further so the sky fades out).
constexpr double kNeuralMinMuS = -0.35;

struct NeuralEvaluator {
    double bottom = 6360e3;
    double top = 6460e3;
    double mie_g = 0.8;
    Vec3d ground_albedo;
    NeuralEncoding encoding = NeuralEncoding::kThesis;
    NeuralTransmittanceNet transmittance;
    NeuralScatteringNet scattering;

    ATMOS_HD Rgb Transmittance(double r, double mu) const {
        float x[kNeuralMaxInputs];
        NeuralEncodeTransmittance(r - bottom, top - bottom, mu, x);
        float t[kNeuralOutputs];
        transmittance.Evaluate(x, t);
        return Rgb(t[0], t[1], t[2]);
    }

    ATMOS_HD Rgb Scattering(double r, double mu, double mu_s, double nu) const {
        if (mu_s < kNeuralMinMuS) return Rgb(0.0f);
        float x[kNeuralMaxInputs];
        NeuralEncodeScattering(encoding, r - bottom, top - bottom, bottom, mie_g, mu, mu_s, nu, x);
        float s[kNeuralOutputs];
        scattering.Evaluate(x, s);
        return Rgb(s[0], s[1], s[2]);
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, bottom, top, &out, &seg)) {
            // A camera on the ground looking down (physics/ray.h): the ground at the camera.
            const double mu_s_g = ClampCosine(Dot(Normalize(camera), sun));
            if (want_ground && GroundAtCamera(seg) && mu_s_g > 0.0) {
                const float k = static_cast<float>(mu_s_g / kPi);
                out.ground =
                    Rgb(static_cast<float>(ground_albedo.x), static_cast<float>(ground_albedo.y),
                        static_cast<float>(ground_albedo.z)) *
                    Transmittance(bottom, mu_s_g) * k;
            }
            return out;
        }
        // Viewer moved to the atmosphere's boundary (Leenman's 2025 thesis section 9.6.3).
        Vec3d p = camera + dir * seg.t_start;
        double r = Length(p);
        if (r < bottom) {
            p = p * (bottom / r);
            r = bottom;
        }
        r = Min(r, top);
        const double mu = ClampCosine(Dot(p, dir) / r);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        const double nu = ClampCosine(Dot(dir, sun));
        Rgb s_view = Scattering(r, mu, mu_s, nu);
        if (!seg.hits_ground) {
            out.transmittance = Transmittance(r, mu);
            out.sky = s_view;
            return out;
        }
        // Ray reversed (section 9.6.3): both transmittances look along -dir, up.
        const Vec3d g = camera + dir * seg.t_end;
        const double r_g = bottom;
        const double mu_g = ClampCosine(Dot(g, dir) / Length(g));
        const double mu_s_g = ClampCosine(Dot(g, sun) / Length(g));
        const Rgb t_viewer = Transmittance(r, -mu);
        const Rgb t_intersect = Transmittance(r_g, -mu_g);
        // Eq. 43: T = T_intersect / T_viewer (reversed), at most 1.
        Rgb t;
        t.x = Min(t_intersect.x / Max(t_viewer.x, 1e-30f), 1.0f);
        t.y = Min(t_intersect.y / Max(t_viewer.y, 1e-30f), 1.0f);
        t.z = Min(t_intersect.z / Max(t_viewer.z, 1e-30f), 1.0f);
        out.transmittance = t;
        // Eq. 44: S = S_viewer - S_intersect T.
        const Rgb s_ground = Scattering(r_g, mu_g, mu_s_g, nu);
        out.sky = Max(s_view - s_ground * t, Rgb(0.0f));
        if (want_ground && mu_s_g > 0.0) {
            const Rgb t_sun = Transmittance(r_g, mu_s_g);
            const float k = static_cast<float>(mu_s_g / kPi);
            out.ground =
                Rgb(static_cast<float>(ground_albedo.x), static_cast<float>(ground_albedo.y),
                    static_cast<float>(ground_albedo.z)) *
                t_sun * t * k;
        }
        return out;
    }
};

// The weights of both networks and what they were fitted for (host side).
struct NeuralWeights {
    NeuralEncoding encoding = NeuralEncoding::kThesis;
    NeuralTransmittanceNet transmittance;
    NeuralScatteringNet scattering;
    // Fingerprint of the atmosphere the weights were fitted to.
    double bottom_radius = 0.0;
    double top_radius = 0.0;
    double mie_phase_g = 0.0;
    Vec3d rayleigh_scattering, mie_scattering, mie_extinction, absorption_extinction;
    // The whole atmosphere of the fit (JSON "fit_atmosphere"; older files
    // lack it and are refused by CheckNeuralWeightsMatch).
    bool has_fit_atmosphere = false;
    AtmosphereParameters fit_atmosphere;
    std::string training_json = "{}";  // free-form record of the fit (JSON object text)
};

// JSON (nlohmann_json): parse / write. Parse throws atmos::Error naming the
// first problem (`source` names the file in messages).
// The encodings' names in weight files and `atmos fit --encoding`: thesis,
// extended, horizon.
const char* NeuralEncodingName(NeuralEncoding encoding);
// The encoding named `name`; false for any other text.
bool ParseNeuralEncoding(const std::string& name, NeuralEncoding* encoding);

NeuralWeights NeuralWeightsFromJson(const std::string& text, const std::string& source);
std::string NeuralWeightsToJson(const NeuralWeights& weights);
NeuralWeights LoadNeuralWeights(const std::string& path);
// The weights shipped in data/neural/<name>.json (embedded at build time).
NeuralWeights EmbeddedNeuralWeights(const std::string& name);
// Throws atmos::Error naming mie_phase_weight2 unless it is 0: the network's
// encoding (NeuralEncodeScattering) carries one Cornette-Shanks lobe.
void CheckNeuralSingleMieLobe(const AtmosphereParameters& atmosphere);
// Throws atmos::Error when `weights` were fitted to another atmosphere: every
// field the fit depends on (all but solar_irradiance: the networks give
// radiance per unit solar irradiance) is compared, and the message names the
// fields that differ and `atmos fit`.
void CheckNeuralWeightsMatch(const NeuralWeights& weights, const AtmosphereParameters& atmosphere,
                             const std::string& source);
NeuralEvaluator MakeNeuralEvaluator(const NeuralWeights& weights,
                                    const AtmosphereParameters& atmosphere);

struct NeuralOptions {
    std::string network = "thesis";  // shipped weights: thesis | large
    std::string weights;             // weights JSON of `atmos fit` (empty: the shipped ones)
};

class NeuralModel : public SimpleEvaluatorModel<NeuralModel, NeuralEvaluator> {
  public:
    static const OptionTable<NeuralOptions>& OptionRows();
    explicit NeuralModel(const NeuralOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;

  private:
    std::string weights_path_;
    std::string network_;
};

}  // namespace atmos
