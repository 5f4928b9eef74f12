// atmos io: reading the lines of a small CSV and splitting one (the query files of `atmos sample`,
// the times and places of `atmos sun`).
#pragma once

#include <cstddef>
#include <string>
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

// Takes the next line that is not blank (only spaces and tabs) off the front of
// *text into *line, without its '\r'; *lines counts every line taken, blank or
// not. False when *text has no such line left.
inline bool NextCsvLine(std::string_view* text, std::string_view* line, int* lines) {
    while (!text->empty()) {
        const size_t eol = text->find('\n');
        *line = text->substr(0, eol);
        *text = eol == std::string_view::npos ? std::string_view() : text->substr(eol + 1);
        ++*lines;
        if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
        if (line->find_first_not_of(" \t") != std::string_view::npos) return true;
    }
    return false;
}

// `line` is `header` once its spaces and tabs are removed.
inline bool IsCsvHeader(std::string_view line, std::string_view header) {
    std::string compact;
    for (char c : line) {
        if (c != ' ' && c != '\t') compact += c;
    }
    return compact == header;
}

}  // namespace atmos
