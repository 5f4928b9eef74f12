// atmos io: the queries and answers of `atmos sample`: CSV (header
// altitude_m,mu,mu_s,azimuth_deg) or NPY of shape (N, 4) in, CSV (the queries
// echoed, then L_r,L_g,L_b,T_r,T_g,T_b) or NPY float32 (N, 6) out.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "atmos/model.h"

namespace atmos {

// The queries of a CSV text: the header line, then one query per line (blank
// lines skipped; fields trimmed of spaces and tabs). atmos::Error names the line,
// the column and the range.
std::vector<SampleQuery> ParseQueriesCsv(std::string_view text);
bool IsNpyPath(const std::string& path);
// The queries of a .npy file of shape (N, 4), of a CSV file, or of stdin ("" or "-").
std::vector<SampleQuery> ReadQueries(const std::string& input);
// The answers as CSV text, one buffer ("%.17g" queries, "%.9g" answers).
std::string FormatAnswersCsv(const std::vector<SampleQuery>& queries,
                             const std::vector<SampleAnswer>& answers);
// To `output` (.npy: float32 (N, 6); other names: CSV written atomically; "" or
// "-": CSV to stdout).
void WriteAnswers(const std::string& output, const std::vector<SampleQuery>& queries,
                  const std::vector<SampleAnswer>& answers);

}  // namespace atmos
