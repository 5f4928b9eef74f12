// atmos io: splitting one line of a small CSV (the query files of `atmos sample`,
// the times and places of `atmos sun`).
#pragma once

#include <cstddef>
#include <string_view>

namespace atmos {

// `s` without leading and trailing spaces and tabs.
inline std::string_view TrimBlanks(std::string_view s) {
    const size_t b = s.find_first_not_of(" \t");
    if (b == std::string_view::npos) return {};
    return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// Splits `line` at commas into at most `max` trimmed fields and returns how many
// fields the line has (possibly more than `max`: the caller names the count in
// its error). With `trailing_comma_ends`, a comma at the end adds no field.
inline size_t SplitCsvFields(std::string_view line, std::string_view* fields, size_t max,
                             bool trailing_comma_ends) {
    size_t count = 0;
    for (;;) {
        const size_t comma = line.find(',');
        if (count < max) fields[count] = TrimBlanks(line.substr(0, comma));
        ++count;
        if (comma == std::string_view::npos) break;
        line = line.substr(comma + 1);
        if (trailing_comma_ends && line.empty()) break;
    }
    return count;
}

}  // namespace atmos
