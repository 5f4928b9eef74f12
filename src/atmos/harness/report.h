// atmos: the offline HTML report of `atmos compare` (index.html).
//
// One self-contained page (no scripts, styles or fonts from the network; the
// images are the files compare writes beside it): the parameters and the
// machine; "which model?" (issue 22): a summary table ranked by mean FLIP with
// ties within the reference's noise (ranking.h), and an inline-SVG plot of
// accuracy against cost with the Pareto front; the FLIP and RMSE tables with
// the best of each row marked only when its lead exceeds the reference's
// noise (tied models marked together) and views outside a model's validity
// flagged; a log-scale chart of render times (the reference's apart); the
// significant lines of code next to the thesis's; and per view colour bars
// with units, a row with the reference, each model, its FLIP map and its
// error image, and luminance profiles through the sun and along the horizon.
// Plots are SVG written here (svg.h), every mark with a <title> giving its
// values. A small inline script records in the page (#image-check:
// data-loaded / data-total images, data-plots SVG plots, data-errors script
// errors and console.error calls) for the headless-browser test.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "harness/compare.h"

namespace atmos {

void WriteCompareReport(const std::string& path, const CompareConfig& config,
                        const CompareResult& result);

// One model's line of the summary table and of accuracy_cost.csv.
struct CompareSummary {
    std::string model;       // the spec (column name)
    double mean_flip = 0.0;  // over the views
    double worst_flip = 0.0;
    std::string worst_view;
    int unresolved_views = 0;          // views where its FLIP is at or below the reference's noise
    double frame_seconds = 0.0;        // mean render time per view at the report's size
    double frame_seconds_1080p = 0.0;  // that, times 1920 * 1080 / (width * height)
    double prepare_seconds = 0.0;      // 0: nothing to prepare or not known
    int64_t table_bytes = -1;          // CompareResult::table_bytes
    int lines = -1;                    // significant lines of code of its model
    int rank = 0;                      // TiedRanks of mean_flip, noise = MeanReferenceNoise
    // On the Pareto front of (frame_seconds, mean_flip) among the eligible
    // models: not a baseline (ModelCapabilities::baseline) and inside its
    // declared validity in every view; pareto_apart says why one is not eligible.
    bool pareto = false;
    std::string pareto_apart;
    std::string validity;  // the views outside its declared validity
};

// The mean over the views of the reference's noise (HDR-FLIP between its
// halves), the tie tolerance of the mean FLIP; -1 when not measured.
double MeanReferenceNoise(const CompareResult& result);
std::vector<CompareSummary> SummarizeCompare(const CompareConfig& config,
                                             const CompareResult& result);
// accuracy_cost.csv: the summary, one row per model, in the models' order.
void WriteAccuracyCostCsv(const std::string& path, const CompareConfig& config,
                          const CompareResult& result);

}  // namespace atmos
