// atmos: root-mean-square error and PSNR between two images.
//
// Source: Leenman's 2025 thesis section 11.5, Eq. 61: RMSE = sqrt(sum_i (v_model,i - v_ref,i)^2 /
// N), applied per colour channel (N = pixels) and over all channels (N = 3 x pixels). The per-pixel
// map stores |v_model - v_ref| per channel (the square root of one squared sample), as the thesis's
// RMSE images. PSNR = 10 log10(peak^2 / MSE) with MSE over all channels; +inf for identical images.
// Sums run in double.
#pragma once

#include "atmos/image.h"

namespace atmos {

struct RmseResult {
    double channel[3] = {0.0, 0.0, 0.0};  // R, G, B
    double overall = 0.0;
    double mse = 0.0;  // over all channels
};

// Throws atmos::Error if the sizes differ or an image is empty.
RmseResult ComputeRmse(const Image& reference, const Image& test);
// Peak signal-to-noise ratio in dB for a signal peak (1 for LDR images); +inf when mse is 0.
double Psnr(double mse, double peak = 1.0);
// |test - reference| per pixel and channel.
Image AbsoluteErrorImage(const Image& reference, const Image& test);

}  // namespace atmos
