// atmos: wide channel batches (docs/architecture.md "Spectral rendering",
// docs/performance.md "Wide channel batches").
//
// A spectral run evaluates N wavelengths. The three-channel path prepares and
// evaluates one model per batch of three, so each ray's geometry (distances,
// densities, table coordinates, phase functions) is computed N / 3 times. A
// wide evaluator takes all the channels of up to kMaxWideChannels / 3 batches
// at once: the geometry once per ray, then a loop over the channels (plain
// float arrays, contiguous per texel, which the compiler vectorises).
//
// The channels are the batches' channels side by side: channel 3b + c is
// channel c of batch b, computed by the same operations in the same order as
// the three-channel evaluator's channel c, so a wide run equals the batched
// run bit for bit (tests/wide_channels_test.cpp).
//
// Everything here is ATMOS_HD and trivially copyable (fixed-size arrays, no
// allocation), like every per-pixel type; the wide loops themselves run on the
// CPU (render/wide.h).
#pragma once

#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "atmos/model.h"
#include "base/texture.h"

namespace atmos {

// The per-channel coefficients of a wide batch: the Vec3d fields of each
// batch's AtmosphereParameters (those a SpectralAtmosphere sets per
// wavelength), side by side. The other fields are the batches' common ones.
struct WideCoefficients {
    int channels = 0;  // 3 x batches
    double rayleigh_scattering[kMaxWideChannels] = {};
    double mie_scattering[kMaxWideChannels] = {};
    double mie_extinction[kMaxWideChannels] = {};
    double absorption_extinction[kMaxWideChannels] = {};
    double ground_albedo[kMaxWideChannels] = {};
    double solar_irradiance[kMaxWideChannels] = {};

    // The largest ground albedo of batch b's three channels (the three-channel
    // evaluators' MaxComponent(atm.ground_albedo)).
    ATMOS_HD double BatchMaxAlbedo(int b) const {
        const double* a = ground_albedo + 3 * b;
        return Max(a[0], Max(a[1], a[2]));
    }
};

// Batch b's coefficients at channels 3b .. 3b + 2. Throws atmos::Error for no
// batches, more than kMaxWideChannels channels, or batches that differ in
// anything but those coefficients (naming the first such field).
WideCoefficients MakeWideCoefficients(const std::vector<AtmosphereParameters>& batches);

// What a wide evaluator returns for one ray: RayResult (physics/ray.h) per
// channel.
struct WideRayResult {
    float sky[kMaxWideChannels];
    float ground[kMaxWideChannels];
    float transmittance[kMaxWideChannels];
    bool hits_ground = false;

    // A ray that meets nothing yet: no sky, no ground, full transmittance in
    // channels [0, n).
    ATMOS_HD void Reset(int n) {
        for (int c = 0; c < n; ++c) {
            sky[c] = 0.0f;
            ground[c] = 0.0f;
            transmittance[c] = 1.0f;
        }
    }
};

// ---- lookups of a table of n channels (n <= kMaxWideChannels) ----
// The operations of BilinearChannel / SampleBilinearFixed / BrunetonSample4D
// (base/texture.h, models/bruneton.h) per channel, in their order: a wide
// lookup's channel 3b + c equals the three-channel lookup's channel c of a
// table holding batch b's channels.

// Bilinear along x then y between rows row0, row1 (texel indices of x = 0).
ATMOS_HD inline void WideBilinear(const float* __restrict__ data, int n, size_t row0, size_t row1,
                                  const TexelSpan& x, float fy, float* __restrict__ out) {
    const float* a0 = data + (row0 + x.i0) * n;
    const float* a1 = data + (row0 + x.i1) * n;
    const float* b0 = data + (row1 + x.i0) * n;
    const float* b1 = data + (row1 + x.i1) * n;
    const float fx = x.f;
    for (int c = 0; c < n; ++c) {
        const float a = a0[c] * (1.0f - fx) + a1[c] * fx;
        const float b = b0[c] * (1.0f - fx) + b1[c] * fx;
        out[c] = a * (1.0f - fy) + b * fy;
    }
}

// SampleBilinearRgb of a 2D table (layer 0) of n channels at (u, v).
ATMOS_HD inline void WideSampleBilinear(const TableView& t, double u, double v, float* out) {
    const TexelSpan x = SplitSpan(u, t.width);
    const TexelSpan y = SplitSpan(v, t.height);
    const size_t w = static_cast<size_t>(t.width);
    WideBilinear(t.data, t.channels, static_cast<size_t>(y.i0) * w, static_cast<size_t>(y.i1) * w,
                 x, y.f, out);
}

// What PrepareWide leaves in a model without tables: its wide evaluator,
// batch 0's atmosphere (the common fields) and the batches' coefficients (the
// solar irradiance the pixels take). RenderPreparedWide / SamplePreparedWide
// (render/wide.h) render and sample it.
template <typename Evaluator>
struct PreparedWide {
    bool prepared = false;
    Evaluator evaluator;
    AtmosphereParameters atmosphere;
    WideCoefficients coefficients;
};

}  // namespace atmos
