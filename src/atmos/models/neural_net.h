// atmos: the small multilayer perceptrons of the `neural` model (device side).
//
// Source: Leenman's 2025 thesis section 9.6 (9.6.1 transmittance: one hidden layer of 4,
// sigmoid; 9.6.2 scattering: two hidden layers of 8, exp(-x) on the output),
// inputs as Leenman's 2025 thesis section 9.1 (squared height, cosines).
//
// A network is stored in fixed-size arrays (no std containers, trivially
// copyable) so that evaluators can carry it to the GPU by value. Layer l maps
// n_l inputs to n_{l+1} outputs: y = act(W x + b), W row-major [out][in].
// Hidden layers use the logistic sigmoid; the output layer uses the sigmoid
// (transmittance, values in (0, 1)) or exp(-x) (scattering, values in
// (0, inf), Leenman's 2025 thesis section 9.6.2). Evaluation is in float.
#pragma once

#include "atmos/math.h"

namespace atmos {

enum class NeuralOutput : int { kSigmoid = 0, kExpNeg = 1 };

// Input encodings (the fit records which one the weights expect).
//  kThesis:   transmittance (h^2, mu); scattering (h^2, mu, mu_s, nu) with
//             h = altitude / atmosphere thickness (Leenman's 2025 thesis section 9.1).
//  kExtended: scattering adds h, ln(Cornette-Shanks phase(nu)) / 4 and
//             (mu - mu_horizon(h)); transmittance as kThesis. Beyond the thesis:
//             the halo and the horizon are given to the network as features
//             instead of having to be learnt from nu and mu.
//  kHorizon:  kExtended's first six inputs, then the ray's lowest altitude
//             (signed, negative below the horizon, / thickness, clamped to
//             [-1, 1]) and a step, 1 for a ray below the horizon (it ends on the
//             ground) and 0 above (issue 15). The radiance jumps at the horizon
//             (from the ground: from the whole horizontal path to nothing;
//             from above: the part beyond the tangent point) and, above it,
//             follows the air's density at the lowest point, ~exp(-h_min / H),
//             which is linear in h_min for the exp(-x) output. kExtended's
//             smooth (mu - mu_horizon) made the network blur the jump and the
//             steep limb (issue 15: horizontal rays from the ground near zero,
//             the limb at 99 km 4-5x too bright).
enum class NeuralEncoding : int { kThesis = 0, kExtended = 1, kHorizon = 2 };

constexpr int kNeuralMaxInputs = 8;
constexpr int kNeuralMaxHidden = 32;
constexpr int kNeuralMaxHiddenLayers = 2;
constexpr int kNeuralOutputs = 3;

ATMOS_HD inline float NeuralSigmoid(float x) { return 1.0f / (1.0f + expf(-x)); }

template <int MaxIn, int MaxHidden>
struct NeuralNet {
    static constexpr int kMaxWeights =
        MaxIn * MaxHidden + MaxHidden * MaxHidden + MaxHidden * kNeuralOutputs;
    static constexpr int kMaxBiases = 2 * MaxHidden + kNeuralOutputs;

    int inputs = 0;
    int hidden_layers = 0;   // 1 or 2
    int hidden[2] = {0, 0};  // widths of the hidden layers
    NeuralOutput output = NeuralOutput::kSigmoid;
    float weights[kMaxWeights] = {};  // layer after layer, each row-major [out][in]
    float biases[kMaxBiases] = {};

    // Width of layer l (0 = inputs, hidden_layers + 1 = outputs).
    ATMOS_HD int Width(int l) const {
        if (l == 0) return inputs;
        if (l <= hidden_layers) return hidden[l - 1];
        return kNeuralOutputs;
    }

    ATMOS_HD void Evaluate(const float* in, float out[kNeuralOutputs]) const {
        float a[MaxHidden > MaxIn ? MaxHidden : MaxIn];
        float b[MaxHidden > MaxIn ? MaxHidden : MaxIn];
        for (int i = 0; i < inputs; ++i) a[i] = in[i];
        int w_off = 0;
        int b_off = 0;
        const int layers = hidden_layers + 1;
        for (int l = 0; l < layers; ++l) {
            const int n_in = Width(l);
            const int n_out = Width(l + 1);
            const bool last = l == layers - 1;
            for (int o = 0; o < n_out; ++o) {
                float z = biases[b_off + o];
                const float* row = weights + w_off + o * n_in;
                for (int i = 0; i < n_in; ++i) z += row[i] * a[i];
                if (!last) {
                    b[o] = NeuralSigmoid(z);
                } else if (output == NeuralOutput::kSigmoid) {
                    out[o] = NeuralSigmoid(z);
                } else {
                    // exp(-x), clamped so it stays finite (Leenman's 2025 thesis section 9.6.2).
                    out[o] = expf(-Max(z, -80.0f));
                }
            }
            w_off += n_in * n_out;
            b_off += n_out;
            for (int o = 0; o < n_out && !last; ++o) a[o] = b[o];
        }
    }
};

using NeuralTransmittanceNet = NeuralNet<4, 16>;
using NeuralScatteringNet = NeuralNet<kNeuralMaxInputs, kNeuralMaxHidden>;

// Number of inputs for each encoding.
ATMOS_HD inline int NeuralTransmittanceInputs(NeuralEncoding) { return 2; }
ATMOS_HD inline int NeuralScatteringInputs(NeuralEncoding e) {
    return e == NeuralEncoding::kThesis ? 4 : e == NeuralEncoding::kExtended ? 7 : 8;
}

// Encodes (altitude, mu) for the transmittance network (Leenman's 2025 thesis section 9.1):
// squared normalised height and the view-zenith cosine.
ATMOS_HD inline void NeuralEncodeTransmittance(double altitude, double thickness, double mu,
                                               float* x) {
    const double h = Min(Max(altitude / thickness, 0.0), 1.0);
    x[0] = static_cast<float>(h * h);
    x[1] = static_cast<float>(ClampCosine(mu));
}

// Encodes (altitude, mu, mu_s, nu) for the scattering network. `bottom` is the
// planet radius and `g` the Mie asymmetry (for the kExtended phase feature).
ATMOS_HD inline void NeuralEncodeScattering(NeuralEncoding e, double altitude, double thickness,
                                            double bottom, double g, double mu, double mu_s,
                                            double nu, float* x) {
    const double h = Min(Max(altitude / thickness, 0.0), 1.0);
    x[0] = static_cast<float>(h * h);
    x[1] = static_cast<float>(ClampCosine(mu));
    x[2] = static_cast<float>(ClampCosine(mu_s));
    x[3] = static_cast<float>(ClampCosine(nu));
    if (e != NeuralEncoding::kThesis) {
        x[4] = static_cast<float>(h);
        // Cornette-Shanks phase (Leenman's 2025 thesis section 3.2 / Bruneton's 2017 implementation
        // notes), as a log.
        const double c = ClampCosine(nu);
        const double k = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
        const double phase = k * (1.0 + c * c) / Pow(1.0 + g * g - 2.0 * g * c, 1.5);
        x[5] = static_cast<float>(log(phase) / 4.0);
        const double r = bottom + Max(altitude, 0.0);
        const double ratio = bottom / r;
        const double mu_horizon = -SafeSqrt(1.0 - ratio * ratio);
        const double m = ClampCosine(mu);
        if (e == NeuralEncoding::kExtended) {
            x[6] = static_cast<float>(m - mu_horizon);
        } else {
            // Lowest point of the ray: the camera for mu >= 0, else the point
            // where it is tangent to a sphere of radius r sqrt(1 - mu^2) (below
            // the ground for a ray that hits it: negative altitude).
            const double r_min = m >= 0.0 ? r : r * SafeSqrt(1.0 - m * m);
            x[6] = static_cast<float>(Min(Max((r_min - bottom) / thickness, -1.0), 1.0));
            x[7] = m < mu_horizon ? 1.0f : 0.0f;
        }
    }
}

}  // namespace atmos
