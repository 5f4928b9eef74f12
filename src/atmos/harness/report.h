// atmos: the offline HTML report of `atmos compare` (index.html).
//
// One self-contained page (no scripts, styles or fonts from the network; the
// images are the files compare writes beside it): the parameters and the
// machine, the FLIP and RMSE tables with the best of each row highlighted and
// views outside a model's validity flagged, an inline-SVG bar chart of render
// times, the significant lines of code next to the thesis's, and per view a
// row with the reference, each model, its FLIP map and its error image. A small
// inline script records in the page (#image-check, data-loaded / data-total)
// how many images loaded, for the headless-browser test.
#pragma once

#include <string>

#include "harness/compare.h"

namespace atmos {

void WriteCompareReport(const std::string& path, const CompareConfig& config,
                        const CompareResult& result);

}  // namespace atmos
