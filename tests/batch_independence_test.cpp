// Issue 33 item 1: a query's answer does not depend on the batch it is asked
// in (its size, its order, the other queries), for every registered model,
// bit for bit (Monte Carlo models: the same seed gives the same answer per
// query, their random numbers being keyed by the query, render/render.h
// SampleQueryKey). The models come from the model list, with their default
// options: no model is named here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "render/progressive.h"

namespace atmos {
namespace {

std::vector<SampleQuery> RandomQueries(int n) {
    std::mt19937 rng(33);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<SampleQuery> queries;
    // The query (zenith, sun at the zenith) first, then scattered ones:
    // altitudes from the ground to orbit (inside and outside the atmosphere),
    // views up and down, suns above and below the horizon.
    queries.push_back({0.0, 1.0, 1.0, 0.0});
    while (static_cast<int>(queries.size()) < n) {
        SampleQuery q;
        const double a = unit(rng);
        q.altitude_m = a < 0.8 ? 30e3 * unit(rng) : 100e3 + 300e3 * unit(rng);
        q.mu = -1.0 + 2.0 * unit(rng);
        q.mu_s = -0.3 + 1.3 * unit(rng);
        q.azimuth_deg = 360.0 * unit(rng);
        queries.push_back(q);
    }
    return queries;
}

bool SameBits(const SampleAnswer& a, const SampleAnswer& b) {
    return std::memcmp(&a, &b, sizeof(SampleAnswer)) == 0;
}

std::vector<SampleAnswer> Ask(const Model& model, const std::vector<SampleQuery>& queries,
                              uint64_t seed) {
    if (!model.Info().capabilities.stochastic) return model.Sample(queries);
    MonteCarloSettings mc;
    mc.spp = 16;
    mc.seed = seed;
    return SampleMonteCarlo(model, queries, mc);
}

class EveryModelBatch : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryModelBatch, AQueryHasTheSameAnswerAloneInABatchAndReversed) {
    std::unique_ptr<Model> model = CreateModel(GetParam());
    model->Prepare(EarthAtmosphere());
    const std::vector<SampleQuery> queries = RandomQueries(50);
    std::vector<SampleQuery> reversed(queries.rbegin(), queries.rend());
    // The batch with its first query asked twice more (neighbours differ).
    std::vector<SampleQuery> repeated = queries;
    repeated.push_back(queries[0]);
    repeated.insert(repeated.begin() + 7, queries[0]);
    for (uint64_t seed : {uint64_t{0}, uint64_t{5}}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const std::vector<SampleAnswer> batch = Ask(*model, queries, seed);
        const std::vector<SampleAnswer> back = Ask(*model, reversed, seed);
        const std::vector<SampleAnswer> again = Ask(*model, repeated, seed);
        ASSERT_EQ(batch.size(), queries.size());
        ASSERT_EQ(back.size(), queries.size());
        ASSERT_EQ(again.size(), repeated.size());
        for (size_t q = 0; q < queries.size(); ++q) {
            SCOPED_TRACE("query " + std::to_string(q));
            const std::vector<SampleAnswer> alone = Ask(*model, {queries[q]}, seed);
            ASSERT_EQ(alone.size(), 1u);
            EXPECT_TRUE(SameBits(alone[0], batch[q]))
                << "alone " << alone[0].radiance[0] << ", in the batch " << batch[q].radiance[0];
            EXPECT_TRUE(SameBits(back[queries.size() - 1 - q], batch[q]))
                << "reversed " << back[queries.size() - 1 - q].radiance[0] << ", in order "
                << batch[q].radiance[0];
            // Monte Carlo models only draw per query: no check that seeds differ here.
        }
        EXPECT_TRUE(SameBits(again[7], batch[0]));
        EXPECT_TRUE(SameBits(again.back(), batch[0]));
        if (!model->Info().capabilities.stochastic) break;  // the seed changes nothing
    }
}

std::vector<std::string> ModelNames() {
    std::vector<std::string> names;
    for (const ModelInfo& info : ListModels()) names.push_back(info.name);
    return names;
}

INSTANTIATE_TEST_SUITE_P(BatchIndependence, EveryModelBatch, ::testing::ValuesIn(ModelNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                             std::string name = p.param;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

}  // namespace
}  // namespace atmos
