// Tests of LUT sampling and table files.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "atmos/error.h"
#include "base/texture.h"
#include "io/table_io.h"

namespace atmos {
namespace {

// Table storage (base/table_storage.h): zeroed on Resize, aligned to 64 bytes,
// and from 8 MiB on (Linux) to 2 MiB, the storage advised for huge pages; a
// copy holds the same values in its own storage.
TEST(Texture, TableStorageIsZeroedAlignedAndCopied) {
    Table small(16, 16, 1, 4);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(small.data()) % 64, 0u);
    Table large(1024, 1024, 1, 3);  // 12 MiB
#if defined(__linux__)
    const char* off = std::getenv("ATMOS_HUGE_PAGES");
    if (!(off && std::string(off) == "0")) {
        EXPECT_EQ(reinterpret_cast<uintptr_t>(large.data()) % (uintptr_t{2} << 20), 0u);
    }
#endif
    for (size_t i = 0; i < large.size(); i += 4099) ASSERT_EQ(large.data()[i], 0.0f) << i;
    large.data()[large.size() - 1] = 7.0f;
    const Table copy = large;
    EXPECT_NE(copy.data(), large.data());
    EXPECT_EQ(copy.data()[copy.size() - 1], 7.0f);
}

TEST(Texture, UnitRangeMappingRoundTripsAndHitsTexelCentres) {
    for (int n : {2, 8, 256}) {
        EXPECT_DOUBLE_EQ(GetTextureCoordFromUnitRange(0.0, n), 0.5 / n);
        EXPECT_DOUBLE_EQ(GetTextureCoordFromUnitRange(1.0, n), 1.0 - 0.5 / n);
        for (double x : {0.0, 0.3, 1.0}) {
            EXPECT_NEAR(GetUnitRangeFromTextureCoord(GetTextureCoordFromUnitRange(x, n), n), x,
                        1e-15);
        }
    }
}

TEST(Texture, BilinearReproducesALinearFunctionAndClampsAtEdges) {
    // f(x, y) = 2 x + 3 y stored at texel centres is reproduced exactly inside.
    Table t(5, 4, 1, 1);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 5; ++x) t.Texel(x, y)[0] = static_cast<float>(2 * x + 3 * y);
    const TableView v = t.view();
    EXPECT_NEAR(v.SampleBilinear((1.5 + 0.5) / 5.0, (2.25 + 0.5) / 4.0).x, 2 * 1.5 + 3 * 2.25,
                1e-5);
    EXPECT_FLOAT_EQ(v.SampleBilinear(0.0, 0.0).x, 0.0f);   // clamp to the first texel
    EXPECT_FLOAT_EQ(v.SampleBilinear(1.0, 1.0).x, 17.0f);  // and to the last
    EXPECT_FLOAT_EQ(v.SampleBilinear(-3.0, 9.0).x, 9.0f);  // far outside
}

TEST(Texture, TrilinearInterpolatesLayers) {
    Table t(2, 2, 3, 2);
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) t.Set(x, y, z, {static_cast<float>(z), 1.0f, 0, 0});
    EXPECT_NEAR(t.view().SampleTrilinear(0.5, 0.5, (0.75 + 0.5) / 3.0).x, 0.75, 1e-6);
    EXPECT_FLOAT_EQ(t.view().SampleTrilinear(0.5, 0.5, 0.5).y, 1.0f);
}

// Issue 19: the fixed-layout samplers (the renderers' lookups) give the bits of
// the generic ones, at random and out-of-range coordinates, for tables with
// one or more texels along each axis.
TEST(Texture, FixedLayoutSamplersAreBitIdenticalToTheGenericOnes) {
    std::mt19937 rng(19);
    std::uniform_real_distribution<double> coord(-0.2, 1.2);
    std::uniform_real_distribution<float> value(0.0f, 3.0f);
    const int sizes[][3] = {{5, 4, 3}, {1, 2, 2}, {2, 1, 1}, {7, 9, 4}};
    for (const auto& n : sizes) {
        Table t3(n[0], n[1], n[2], 3), t4(n[0], n[1], n[2], 4);
        for (size_t i = 0; i < t3.size(); ++i) t3.data()[i] = value(rng);
        for (size_t i = 0; i < t4.size(); ++i) t4.data()[i] = value(rng);
        const TableView v3 = t3.view(), v4 = t4.view();
        for (int i = 0; i < 2000; ++i) {
            const double u = i % 97 == 0 ? 1.0 : coord(rng), v = coord(rng), w = coord(rng);
            const Rgb fixed = SampleBilinearRgb(v3, u, v);
            const Rgb generic = v3.SampleBilinear(u, v).rgb();
            for (int c = 0; c < 3; ++c) ASSERT_EQ(fixed[c], generic[c]) << u << " " << v;
            const TexelSpan x = SplitSpan(u, n[0]), y = SplitSpan(v, n[1]), z = SplitSpan(w, n[2]);
            float f3[3], f4[4];
            SampleTrilinearFixed<3>(v3.data, n[0], n[1], x, y, z, f3);
            SampleTrilinearFixed<4>(v4.data, n[0], n[1], x, y, z, f4);
            const Vec4f g3 = v3.SampleTrilinear(u, v, w), g4 = v4.SampleTrilinear(u, v, w);
            ASSERT_EQ(f3[0], g3.x);
            ASSERT_EQ(f3[1], g3.y);
            ASSERT_EQ(f3[2], g3.z);
            ASSERT_EQ(f4[0], g4.x);
            ASSERT_EQ(f4[1], g4.y);
            ASSERT_EQ(f4[2], g4.z);
            ASSERT_EQ(f4[3], g4.w);
        }
    }
}

TEST(TableIo, ExrRoundTripIsExact) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    const std::filesystem::path dir =
        env ? std::filesystem::path(env) : std::filesystem::temp_directory_path() / "atmos_test";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "table_roundtrip.exr").string();
    Table t(7, 3, 4, 3);
    for (size_t i = 0; i < t.size(); ++i) t.data()[i] = 1e-7f * static_cast<float>(i * i) + 0.25f;
    WriteTableExr(t, path);
    const Table back = ReadTableExr(path, 4, 3);
    ASSERT_EQ(back.width(), 7);
    ASSERT_EQ(back.depth(), 4);
    for (size_t i = 0; i < t.size(); ++i) ASSERT_EQ(back.data()[i], t.data()[i]) << i;
    EXPECT_THROW(ReadTableExr(path, 3, 3), Error);  // 28 columns are not 3 layers
    EXPECT_THROW(ReadTableExr(path, 4, 4), Error);  // no A channel
    EXPECT_THROW(ReadTableExr((dir / "missing.exr").string(), 1, 1), Error);
}

}  // namespace
}  // namespace atmos
