// atmos: RMSE and PSNR (Leenman's 2025 thesis section 11.5, Eq. 61).
#include "metrics/rmse.h"

#include <cmath>
#include <limits>

#include "atmos/error.h"

namespace atmos {

namespace {
void CheckPair(const Image& a, const Image& b) {
    if (a.empty() || b.empty()) Fail("RMSE needs two non-empty images");
    if (a.width() != b.width() || a.height() != b.height()) {
        Fail("RMSE needs images of the same size (reference ", a.width(), "x", a.height(),
             ", test ", b.width(), "x", b.height(), ")");
    }
    for (const Image* img : {&a, &b}) {
        for (size_t i = 0; i < img->size(); ++i) {
            if (!std::isfinite(img->data()[i])) {
                Fail("RMSE: the ", img == &a ? "reference" : "test",
                     " image holds a NaN or infinite value");
            }
        }
    }
}
}  // namespace

RmseResult ComputeRmse(const Image& reference, const Image& test) {
    CheckPair(reference, test);
    double sum[3] = {0.0, 0.0, 0.0};
    const float* a = reference.data();
    const float* b = test.data();
    const size_t pixels = reference.size() / 3;
    for (size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double d = static_cast<double>(b[3 * i + c]) - static_cast<double>(a[3 * i + c]);
            sum[c] += d * d;
        }
    }
    RmseResult r;
    const double n = static_cast<double>(pixels);
    for (int c = 0; c < 3; ++c) r.channel[c] = std::sqrt(sum[c] / n);
    r.mse = (sum[0] + sum[1] + sum[2]) / (3.0 * n);
    r.overall = std::sqrt(r.mse);
    return r;
}

double Psnr(double mse, double peak) {
    if (mse <= 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peak * peak / mse);
}

Image AbsoluteErrorImage(const Image& reference, const Image& test) {
    CheckPair(reference, test);
    Image out(reference.width(), reference.height());
    const float* a = reference.data();
    const float* b = test.data();
    float* o = out.data();
    for (size_t i = 0; i < reference.size(); ++i) o[i] = std::fabs(b[i] - a[i]);
    return out;
}

}  // namespace atmos
