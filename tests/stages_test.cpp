// The precomputation loop (render/stages.h): RunStage calls every item once on
// the CPU, reads and writes through the stage's tables, and logs the run.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "base/texture.h"
#include "render/stages.h"
#include "test_util.h"

namespace atmos {
namespace {

// out(x, y) = 2 * in(x, y) + out(x, y) + x: reads an input, accumulates into the output.
struct ScaleAddStage : atmos_test::InOutStage {
    ATMOS_HD void operator()(int64_t i) const {
        const int x = static_cast<int>(i % out.width);
        const int y = static_cast<int>(i / out.width);
        const Vec4f a = in.Fetch(x, y);
        float* p = out.Texel(x, y);
        p[0] += 2.0f * a.x + static_cast<float>(x);
        p[1] += 2.0f * a.y;
    }
};

TEST(Stages, RunStageVisitsEveryItemOnceOnTheCpuAndLogsIt) {
    Table in(7, 5, 1, 2), out(7, 5, 1, 2);
    for (size_t i = 0; i < in.size(); ++i) in.data()[i] = static_cast<float>(i);
    for (size_t i = 0; i < out.size(); ++i) out.data()[i] = 1.0f;
    std::vector<StageTime> log;
    {
        const StageLogScope scope(&log);
        RunStage("scale-add", 35, 3, ScaleAddStage{in.view(), out.out(true)});
    }
    for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 7; ++x) {
            const size_t k = (static_cast<size_t>(y) * 7 + x) * 2;
            EXPECT_FLOAT_EQ(out.data()[k], 1.0f + 2.0f * static_cast<float>(k) + x);
            EXPECT_FLOAT_EQ(out.data()[k + 1], 1.0f + 2.0f * static_cast<float>(k + 1));
        }
    }
    ASSERT_EQ(log.size(), 1u);
    EXPECT_EQ(log[0].name, "scale-add");
    EXPECT_EQ(log[0].items, 35);
    EXPECT_EQ(log[0].backend, "cpu");
    EXPECT_GE(log[0].kernel_ms, 0.0);
    // Without a scope nothing is logged; an empty range does nothing.
    RunStage("scale-add", 35, 3, ScaleAddStage{in.view(), out.out(true)});
    RunStage("none", 0, 1, ScaleAddStage{in.view(), out.out()});
    EXPECT_EQ(log.size(), 1u);
}

TEST(Stages, TableOutWritesWhatTableViewReads) {
    Table t(3, 2, 2, 3);
    const TableOut o = t.out();
    o.Set(2, 1, 1, {1.0f, 2.0f, 3.0f, 4.0f});
    const Vec4f v = t.view().Fetch(2, 1, 1);
    EXPECT_EQ(v.x, 1.0f);
    EXPECT_EQ(v.y, 2.0f);
    EXPECT_EQ(v.z, 3.0f);
    EXPECT_EQ(v.w, 0.0f);  // three channels: w is not stored
    EXPECT_EQ(o.size(), t.size());
    EXPECT_EQ(o.view().data, t.view().data);
}

}  // namespace
}  // namespace atmos
