// Tests of the image metrics: FLIP (spec /work/shared/specs/flip.md) and RMSE/PSNR.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "atmos/error.h"
#include "atmos/image.h"
#include "metrics/flip.h"
#include "metrics/rmse.h"

namespace atmos {
namespace {

// A sky-like HDR test image: a vertical gradient, a bright disc and a few
// sharp stripes (features for the edge/point detectors).
Image SkyImage(int w, int h, float scale = 1.0f) {
    Image img(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const float t = static_cast<float>(y) / static_cast<float>(h);
            Rgb c(0.2f + 0.6f * t, 0.35f + 0.5f * t, 0.9f - 0.3f * t);
            const float dx = static_cast<float>(x - w / 3), dy = static_cast<float>(y - h / 3);
            if (dx * dx + dy * dy < 36.0f) c = Rgb(8.0f, 7.0f, 6.0f);
            if ((x / 4) % 5 == 0 && y > h / 2) c = c * 0.3f;
            img.Set(x, y, c * scale);
        }
    }
    return img;
}

Image Shifted(const Image& in, int dx) {
    Image out(in.width(), in.height());
    for (int y = 0; y < in.height(); ++y) {
        for (int x = 0; x < in.width(); ++x) {
            out.Set(x, y, in.Get(std::min(std::max(x - dx, 0), in.width() - 1), y));
        }
    }
    return out;
}

Image Blurred(const Image& in) {  // 5x5 box blur, clamped borders
    Image out(in.width(), in.height());
    for (int y = 0; y < in.height(); ++y) {
        for (int x = 0; x < in.width(); ++x) {
            Rgb s(0.0f, 0.0f, 0.0f);
            for (int j = -2; j <= 2; ++j) {
                for (int i = -2; i <= 2; ++i) {
                    s += in.Get(std::min(std::max(x + i, 0), in.width() - 1),
                                std::min(std::max(y + j, 0), in.height() - 1));
                }
            }
            out.Set(x, y, s / 25.0f);
        }
    }
    return out;
}

Image Uniform(int w, int h, Rgb c) {
    Image img(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) img.Set(x, y, c);
    }
    return img;
}

TEST(Flip, IdenticalImagesScoreZero) {
    const Image a = SkyImage(64, 40);
    const FlipResult hdr = HdrFlip(a, a);
    EXPECT_EQ(hdr.mean, 0.0);
    for (float v : hdr.map) ASSERT_EQ(v, 0.0f);
    Image ldr_img = SkyImage(64, 40, 0.1f);
    const FlipResult ldr = LdrFlip(ldr_img, ldr_img);
    EXPECT_EQ(ldr.mean, 0.0);
}

TEST(Flip, ShiftAndBlurScoreHigherThanOnePercentBrightness) {
    const Image a = SkyImage(96, 64);
    const double bright = HdrFlip(a, SkyImage(96, 64, 1.01f)).mean;
    const double shift = HdrFlip(a, Shifted(a, 2)).mean;
    const double blur = HdrFlip(a, Blurred(a)).mean;
    EXPECT_GT(bright, 0.0);
    EXPECT_GT(shift, bright);
    EXPECT_GT(blur, bright);
    // The same ordering in LDR.
    const Image l = SkyImage(96, 64, 0.1f);
    const double lb = LdrFlip(l, SkyImage(96, 64, 0.101f)).mean;
    EXPECT_GT(LdrFlip(l, Shifted(l, 2)).mean, lb);
    EXPECT_GT(LdrFlip(l, Blurred(l)).mean, lb);
}

TEST(Flip, UniformImagesGiveTheClosedFormColourError) {
    // Uniform images: the normalized CSF leaves them unchanged and the feature
    // kernels (positive and negative taps summing to +1 and -1) give 0, so
    // FLIP = dEc of spec 2.2 steps 3-8. Black vs white: HyAB = |0 - 100| = 100.
    const double cmax = 41.2760963, pccmax = 0.4 * cmax;
    const double e = std::pow(100.0, 0.7);
    const double expected = 0.95 + (e - pccmax) / (cmax - pccmax) * 0.05;
    const FlipResult r =
        LdrFlip(Uniform(24, 24, Rgb(0.0f, 0.0f, 0.0f)), Uniform(24, 24, Rgb(1.0f, 1.0f, 1.0f)));
    EXPECT_NEAR(r.mean, expected, 2e-4);
    // Green vs blue is the normalization pair: e = cmax, so FLIP = 1.
    const FlipResult gb =
        LdrFlip(Uniform(24, 24, Rgb(0.0f, 1.0f, 0.0f)), Uniform(24, 24, Rgb(0.0f, 0.0f, 1.0f)));
    EXPECT_NEAR(gb.mean, 1.0, 1e-5);
}

TEST(Flip, ConstantsOfTheSpec) {
    EXPECT_NEAR(FlipDefaultPpd(), 67.0206451, 1e-5);
    EXPECT_NEAR(FlipPixelsPerDegree(0.7, 0.7, 3840.0), 67.0206433, 1e-5);
    EXPECT_NEAR(FlipMaxColorDistance(), 41.2760963, 1e-4);
    EXPECT_NEAR(FlipToneMapperThreshold(FlipToneMapper::kAces), 2.11887312, 1e-6);
    EXPECT_NEAR(FlipToneMapperThreshold(FlipToneMapper::kHable), 3.12774992, 1e-6);
    EXPECT_NEAR(FlipToneMapperThreshold(FlipToneMapper::kReinhard), 5.66666794, 1e-5);
    // The threshold maps to 0.85 through each curve (per channel for a grey pixel).
    for (FlipToneMapper t : {FlipToneMapper::kAces, FlipToneMapper::kHable}) {
        const float x = static_cast<float>(FlipToneMapperThreshold(t));
        EXPECT_NEAR(FlipToneMap(t, Rgb(x, x, x)).x, 0.85f, 1e-5f);
    }
}

TEST(Flip, CsfKernelsSumAsTheSpecSays) {
    EXPECT_EQ(MakeFlipCsfKernels(FlipDefaultPpd()).radius, 10);
    EXPECT_EQ(MakeFlipCsfKernels(30.0).radius, 5);
    EXPECT_EQ(MakeFlipCsfKernels(10.0).radius, 2);
    const double ppd = FlipDefaultPpd();
    const FlipCsfKernels k = MakeFlipCsfKernels(ppd);
    auto sum = [](const std::vector<float>& v) {
        double s = 0.0;
        for (float x : v) s += static_cast<double>(x);
        return s;
    };
    EXPECT_NEAR(sum(k.yy), 1.0, 1e-6);
    EXPECT_NEAR(sum(k.cx), 1.0, 1e-6);
    EXPECT_NEAR(sum(k.cz1) * sum(k.cz1) + sum(k.cz2) * sum(k.cz2), 1.0, 1e-6);
    // Independent check: the unseparated 2-D Cz kernel s(r2) of spec 2.2,
    // normalized to sum 1, equals h1 h1^T + h2 h2^T.
    const int r = k.radius;
    const double pi = 3.14159265358979;
    std::vector<double> s2((2 * r + 1) * (2 * r + 1));
    double total = 0.0;
    for (int j = -r; j <= r; ++j) {
        for (int i = -r; i <= r; ++i) {
            const double r2 = (i / ppd) * (i / ppd) + (j / ppd) * (j / ppd);
            const double v = 34.1 * std::sqrt(pi / 0.04) * std::exp(-pi * pi * r2 / 0.04) +
                             13.5 * std::sqrt(pi / 0.025) * std::exp(-pi * pi * r2 / 0.025);
            s2[(j + r) * (2 * r + 1) + (i + r)] = v;
            total += v;
        }
    }
    for (int j = 0; j <= 2 * r; ++j) {
        for (int i = 0; i <= 2 * r; ++i) {
            const double separable = static_cast<double>(k.cz1[j] * k.cz1[i] + k.cz2[j] * k.cz2[i]);
            ASSERT_NEAR(separable, s2[j * (2 * r + 1) + i] / total, 1e-6);
        }
    }
}

TEST(Flip, FeatureKernelsSumAsTheSpecSays) {
    EXPECT_EQ(MakeFlipFeatureKernels(FlipDefaultPpd()).radius, 9);
    EXPECT_EQ(MakeFlipFeatureKernels(30.0).radius, 4);
    EXPECT_EQ(MakeFlipFeatureKernels(10.0).radius, 2);
    const FlipFeatureKernels k = MakeFlipFeatureKernels(FlipDefaultPpd());
    double g = 0.0, d1p = 0.0, d1n = 0.0, d2p = 0.0, d2n = 0.0;
    for (size_t i = 0; i < k.gauss.size(); ++i) {
        g += static_cast<double>(k.gauss[i]);
        (k.d1[i] > 0.0f ? d1p : d1n) += static_cast<double>(k.d1[i]);
        (k.d2[i] > 0.0f ? d2p : d2n) += static_cast<double>(k.d2[i]);
    }
    EXPECT_NEAR(g, 1.0, 1e-6);
    EXPECT_NEAR(d1p, 1.0, 1e-6);
    EXPECT_NEAR(d1n, -1.0, 1e-6);
    EXPECT_NEAR(d2p, 1.0, 1e-6);
    EXPECT_NEAR(d2n, -1.0, 1e-6);
    // sigma = 0.5 * 0.082 * ppd: the Gaussian's second moment.
    const double sigma = 0.5 * 0.082 * FlipDefaultPpd();
    double m2 = 0.0;
    for (int i = -k.radius; i <= k.radius; ++i) {
        m2 += static_cast<double>(k.gauss[i + k.radius]) * i * i;
    }
    EXPECT_NEAR(std::sqrt(m2), sigma, 0.02 * sigma);  // truncated at 3 sigma
}

TEST(Flip, ExposureRangeFollowsTheClosedForm) {
    // Grey pixels: Y = v (the luminance weights sum to 1). Values 1, 2, 4, 8:
    // Y_max = 8, the median is the element at floor(4/2) = 2 in sorted order: 4.
    Image img(4, 1);
    const float v[4] = {2.0f, 8.0f, 1.0f, 4.0f};
    for (int x = 0; x < 4; ++x) img.Set(x, 0, Rgb(v[x], v[x], v[x]));
    // x_t from the quadratic of spec 3.2, solved here in double.
    const double a = 0.9036 - 0.85 * 0.8748, b = 0.018 - 0.85 * 0.354, c = -0.85 * 0.14;
    const double xt = (-b + std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
    const FlipExposureRange r = FlipComputeExposureRange(img, FlipOptions{});
    EXPECT_NEAR(r.start, std::log2(xt / 8.0), 1e-5);
    EXPECT_NEAR(r.stop, std::log2(xt / 4.0), 1e-5);
    EXPECT_EQ(r.count, 2);  // max(2, ceil(1))
    // A wide range: Y from 1e-3 to 10 -> count = ceil(stop - start).
    Image wide(5, 1);
    const float w[5] = {1e-3f, 1e-2f, 0.1f, 1.0f, 10.0f};
    for (int x = 0; x < 5; ++x) wide.Set(x, 0, Rgb(w[x], w[x], w[x]));
    const FlipExposureRange rw = FlipComputeExposureRange(wide, FlipOptions{});
    EXPECT_NEAR(rw.stop - rw.start, std::log2(10.0 / 0.1), 1e-5);
    EXPECT_EQ(rw.count, static_cast<int>(std::ceil(std::log2(100.0) - 1e-9)));
    // User-given start replaces the computed one alone.
    FlipOptions o;
    o.has_start_exposure = true;
    o.start_exposure = -10.0;
    const FlipExposureRange ru = FlipComputeExposureRange(wide, o);
    EXPECT_EQ(ru.start, -10.0);
    EXPECT_NEAR(ru.stop, rw.stop, 1e-12);
    o.start_exposure = 100.0;
    EXPECT_THROW(FlipComputeExposureRange(wide, o), Error);
}

TEST(Flip, HdrWithBlackPixelsIsFiniteAndCorrect) {
    // Fewer than half black: the median is unaffected, so the result must equal
    // the thesis's workaround (1e-9 added to every pixel).
    Image ref = SkyImage(64, 40), test = SkyImage(64, 40, 1.2f);
    for (int y = 30; y < 40; ++y) {
        for (int x = 0; x < 64; ++x) {
            ref.Set(x, y, Rgb(0.0f, 0.0f, 0.0f));
            test.Set(x, y, Rgb(0.0f, 0.0f, 0.0f));
        }
    }
    Image ref_eps = ref, test_eps = test;
    for (size_t i = 0; i < ref.size(); ++i) {
        ref_eps.data()[i] += 1e-9f;
        test_eps.data()[i] += 1e-9f;
    }
    const FlipResult r = HdrFlip(ref, test);
    ASSERT_TRUE(std::isfinite(r.mean));
    EXPECT_GT(r.mean, 0.01);
    EXPECT_NEAR(r.mean, HdrFlip(ref_eps, test_eps).mean, 1e-4);
    // More than half black (the night side): still finite, in (0, 1], and 0 for identical.
    Image night = ref, night_test = test;
    for (int y = 8; y < 40; ++y) {
        for (int x = 0; x < 64; ++x) {
            night.Set(x, y, Rgb(0.0f, 0.0f, 0.0f));
            night_test.Set(x, y, Rgb(0.0f, 0.0f, 0.0f));
        }
    }
    const FlipResult n = HdrFlip(night, night_test);
    ASSERT_TRUE(std::isfinite(n.mean));
    EXPECT_GT(n.mean, 0.0);
    EXPECT_LE(n.mean, 1.0);
    EXPECT_GE(n.exposures.count, 2);
    EXPECT_EQ(HdrFlip(night, night).mean, 0.0);
    // All black.
    const Image black = Uniform(16, 16, Rgb(0.0f, 0.0f, 0.0f));
    EXPECT_EQ(HdrFlip(black, black).mean, 0.0);
    const FlipResult bw = HdrFlip(black, Uniform(16, 16, Rgb(1.0f, 1.0f, 1.0f)));
    ASSERT_TRUE(std::isfinite(bw.mean));
    EXPECT_GT(bw.mean, 0.5);
}

TEST(Flip, ThesisExposureSetupAddsOneNanoToEveryPixel) {
    // `--exposure thesis` (Leenman's 2025 thesis section 11.5): the same as HDR-FLIP of the
    // images with 1e-9 added to every channel; with more than half of the
    // pixels black its median is ~1e-9, so the exposure range reaches ~30 stops
    // further than atmos's median over the non-black pixels, and the mean
    // differs (the gap to the thesis's Appendix A in orbit and space views).
    // Sky at the top, black below, and a faint band (1e-6, twice as bright in
    // the test) that atmos's exposures (down to the sky's median) leave black.
    Image ref = SkyImage(64, 40), test = SkyImage(64, 40, 1.2f);
    for (int y = 8; y < 40; ++y) {
        for (int x = 0; x < 64; ++x) {
            const float f = y >= 36 ? 1e-6f : 0.0f;
            ref.Set(x, y, Rgb(f, f, f));
            test.Set(x, y, Rgb(2.0f * f, 2.0f * f, 2.0f * f));
        }
    }
    Image ref_eps = ref, test_eps = test;
    for (size_t i = 0; i < ref.size(); ++i) {
        ref_eps.data()[i] += 1e-9f;
        test_eps.data()[i] += 1e-9f;
    }
    FlipOptions thesis;
    thesis.exposure_setup = FlipExposureSetup::kThesis;
    const FlipResult t = HdrFlip(ref, test, thesis);
    const FlipResult eps = HdrFlip(ref_eps, test_eps);
    const FlipResult atmos = HdrFlip(ref, test);
    EXPECT_EQ(t.mean, eps.mean);
    EXPECT_EQ(t.exposures.count, eps.exposures.count);
    EXPECT_GT(t.exposures.stop, atmos.exposures.stop + 20.0);
    EXPECT_GT(t.mean, atmos.mean + 1e-3);  // the faint band's error counts
    EXPECT_STREQ(FlipExposureSetupName(ParseFlipExposureSetup("thesis")), "thesis");
    EXPECT_THROW(ParseFlipExposureSetup("median"), Error);
}

TEST(Flip, RejectsMismatchedSizes) {
    EXPECT_THROW(HdrFlip(Image(4, 4), Image(4, 5)), Error);
    EXPECT_THROW(LdrFlip(Image(), Image()), Error);
    Image nan_image(4, 4);
    nan_image.Set(1, 1, Rgb(std::nanf(""), 0.0f, 0.0f));
    EXPECT_THROW(HdrFlip(Image(4, 4), nan_image), Error);
    EXPECT_THROW(ComputeRmse(nan_image, Image(4, 4)), Error);
}

TEST(Rmse, HandComputedCase) {
    Image ref(2, 1), test(2, 1);
    ref.Set(0, 0, Rgb(0.0f, 0.0f, 0.0f));
    ref.Set(1, 0, Rgb(1.0f, 1.0f, 1.0f));
    test.Set(0, 0, Rgb(1.0f, 0.0f, 0.0f));
    test.Set(1, 0, Rgb(1.0f, 1.0f, 3.0f));
    const RmseResult r = ComputeRmse(ref, test);
    EXPECT_NEAR(r.channel[0], std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(r.channel[1], 0.0, 1e-12);
    EXPECT_NEAR(r.channel[2], std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(r.overall, std::sqrt(5.0 / 6.0), 1e-12);
    EXPECT_NEAR(Psnr(r.mse), 10.0 * std::log10(6.0 / 5.0), 1e-12);
    EXPECT_TRUE(std::isinf(Psnr(ComputeRmse(ref, ref).mse)));
    const Image e = AbsoluteErrorImage(ref, test);
    EXPECT_EQ(e.Get(1, 0).z, 2.0f);
    EXPECT_THROW(ComputeRmse(Image(2, 2), Image(3, 2)), Error);
}

TEST(Flip, MagmaEndsAreDarkAndBright) {
    unsigned char lo[3], hi[3], mid[3];
    FlipMagma(0.0f, lo);
    FlipMagma(1.0f, hi);
    FlipMagma(std::nanf(""), mid);
    EXPECT_LT(lo[0] + lo[1] + lo[2], 10);
    EXPECT_GT(hi[0] + hi[1] + hi[2], 600);
    EXPECT_EQ(mid[0], lo[0]);
}

}  // namespace
}  // namespace atmos
