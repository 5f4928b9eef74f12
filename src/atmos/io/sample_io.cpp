// atmos io: the queries and answers of `atmos sample` (sample_io.h).
#include "io/sample_io.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "atmos/error.h"
#include "atmos/number.h"
#include "io/bounded_read.h"
#include "io/csv_fields.h"
#include "io/image_formats.h"
#include "io/output_path.h"

namespace atmos {

namespace {

constexpr const char* kQueryHeader = "altitude_m,mu,mu_s,azimuth_deg";

// Parses one CSV field as a finite number.
double ParseField(std::string_view text, int line, const char* column) {
    double v = 0.0;
    const NumberError e = ParseNumber(text, &v);  // atmos/number.h: the one parser
    if (e != NumberError::kNone)
        Fail("line ", line, ": ", column, " '", std::string(text), "' ", NumberErrorText(e));
    return v;
}

// The range checks of a query (`where`: "line N" or "row N").
void CheckQuery(const SampleQuery& q, const char* where, int index) {
    if (q.altitude_m < 0.0) Fail(where, " ", index, ": altitude_m must be >= 0");
    if (q.mu < -1.0 || q.mu > 1.0) Fail(where, " ", index, ": mu must be in [-1, 1]");
    if (q.mu_s < -1.0 || q.mu_s > 1.0) Fail(where, " ", index, ": mu_s must be in [-1, 1]");
}

}  // namespace

// The queries of a CSV text: the header line, then one query per line (blank
// lines skipped; fields trimmed of spaces and tabs; a trailing comma ends the
// line).
std::vector<SampleQuery> ParseQueriesCsv(std::string_view text) {
    std::vector<SampleQuery> queries;
    int line_number = 0;
    bool header = false;
    static const char* const kColumns[4] = {"altitude_m", "mu", "mu_s", "azimuth_deg"};
    std::string_view line;
    while (NextCsvLine(&text, &line, &line_number)) {
        if (!header) {
            if (!IsCsvHeader(line, kQueryHeader)) {
                Fail("line ", line_number, ": expected the header '", kQueryHeader, "', got '",
                     std::string(line), "'");
            }
            header = true;
            continue;
        }
        std::string_view fields[4];
        const size_t count = SplitCsvFields(line, fields, 4, /*trailing_comma_ends=*/true);
        if (count != 4) {
            Fail("line ", line_number, ": expected 4 comma-separated numbers, got ", count,
                 " fields");
        }
        SampleQuery q;
        double* values[4] = {&q.altitude_m, &q.mu, &q.mu_s, &q.azimuth_deg};
        for (int i = 0; i < 4; ++i) *values[i] = ParseField(fields[i], line_number, kColumns[i]);
        CheckQuery(q, "line", line_number);
        queries.push_back(q);
    }
    if (!header) Fail("no input: expected the header '", kQueryHeader, "'");
    return queries;
}

namespace {}  // namespace

bool IsNpyPath(const std::string& path) {
    return path.size() >= 4 && path.compare(path.size() - 4, 4, ".npy") == 0;
}

// The queries of a .npy file of shape (N, 4) (columns as the CSV header), or
// of a CSV file, or of stdin ("" or "-").
std::vector<SampleQuery> ReadQueries(const std::string& input) {
    // Bounded in size and line length as they are read (io/bounded_read.h).
    if (input.empty() || input == "-") {
        return ParseQueriesCsv(
            ReadBounded(stdin, "the queries on stdin", kMaxQueryInputBytes, kMaxCsvLineBytes));
    }
    if (!IsNpyPath(input)) {
        return ParseQueriesCsv(ReadFileBounded(input, kMaxQueryInputBytes, kMaxCsvLineBytes));
    }
    const detail::NpyArray a = detail::ReadNpyArray(input);
    if (a.shape.size() != 2 || a.shape[1] != 4) {
        Fail("'", input, "': expected an array of shape (N, 4) (columns ", kQueryHeader,
             "), got shape ", detail::NpyShapeString(a.shape));
    }
    std::vector<SampleQuery> queries(a.values.size() / 4);
    for (size_t i = 0; i < queries.size(); ++i) {
        const double* v = &a.values[4 * i];
        for (int c = 0; c < 4; ++c) {
            if (!std::isfinite(v[c])) Fail("row ", i, ": a value is not a finite number");
        }
        queries[i] = SampleQuery{v[0], v[1], v[2], v[3]};
        CheckQuery(queries[i], "row", static_cast<int>(i));
    }
    return queries;
}

namespace {

// Appends `value` in its shortest form that reads back to the same number
// (std::to_chars without a precision: Ryu, general notation as printf's %g
// chooses it) and `sep`. A double query reads back as the same double, a
// float answer as the same float; "%.17g" / "%.9g" (before 0.3.0) printed
// the same values with more digits at 3x the instructions.
template <typename T>
void AppendNumber(std::string* out, size_t* used, T value, char sep) {
    char* first = out->data() + *used;
    const std::to_chars_result r =
        std::to_chars(first, out->data() + out->size(), value, std::chars_format::general);
    *r.ptr = sep;
    *used = static_cast<size_t>(r.ptr + 1 - out->data());
}

}  // namespace

// The answers as CSV (the queries echoed, then L and T), one buffer.
std::string FormatAnswersCsv(const std::vector<SampleQuery>& queries,
                             const std::vector<SampleAnswer>& answers) {
    static const char kHeader[] = "altitude_m,mu,mu_s,azimuth_deg,L_r,L_g,L_b,T_r,T_g,T_b\n";
    // At most 24 characters per double and 16 per float (shortest form).
    constexpr size_t kMaxRow = 4 * 25 + 6 * 17;
    std::string out(sizeof kHeader - 1 + queries.size() * kMaxRow, '\0');
    std::memcpy(out.data(), kHeader, sizeof kHeader - 1);
    size_t used = sizeof kHeader - 1;
    for (size_t i = 0; i < queries.size(); ++i) {
        const SampleQuery& q = queries[i];
        const SampleAnswer& a = answers[i];
        AppendNumber(&out, &used, q.altitude_m, ',');
        AppendNumber(&out, &used, q.mu, ',');
        AppendNumber(&out, &used, q.mu_s, ',');
        AppendNumber(&out, &used, q.azimuth_deg, ',');
        const float v[6] = {a.radiance.x,      a.radiance.y,      a.radiance.z,
                            a.transmittance.x, a.transmittance.y, a.transmittance.z};
        for (int c = 0; c < 6; ++c) AppendNumber(&out, &used, v[c], c == 5 ? '\n' : ',');
    }
    out.resize(used);
    return out;
}

void WriteAnswers(const std::string& output, const std::vector<SampleQuery>& queries,
                  const std::vector<SampleAnswer>& answers) {
    if (!output.empty() && output != "-" && IsNpyPath(output)) {
        std::vector<float> values(answers.size() * 6);
        for (size_t i = 0; i < answers.size(); ++i) {
            const SampleAnswer& a = answers[i];
            const float v[6] = {a.radiance.x,      a.radiance.y,      a.radiance.z,
                                a.transmittance.x, a.transmittance.y, a.transmittance.z};
            std::memcpy(&values[6 * i], v, sizeof v);
        }
        WriteThroughTemporary(output, [&](const std::string& temporary) {
            detail::WriteNpyArray(temporary, {answers.size(), 6}, values.data());
        });
        return;
    }
    const std::string text = FormatAnswersCsv(queries, answers);
    if (!output.empty() && output != "-") {
        WriteFileAtomically(output, text);  // a temporary file and one rename
        return;
    }
    const bool ok = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
    if (!ok || std::fflush(stdout) != 0) Fail("cannot write the answers to stdout");
}

}  // namespace atmos
