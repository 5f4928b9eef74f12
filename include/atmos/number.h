// atmos: the one number parser of every input (issue 18 item 8).
//
// Options, --set values, `sample` rows and image headers read numbers through
// ParseNumber: decimal text as std::from_chars reads it (no hexadecimal: "0x10"
// is not a number; denormals such as 1e-320 are numbers), an optional leading
// '+', nothing before or after. Values out of double's range, NaN and
// infinities are refused, each with its own reason.
#pragma once

#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>

namespace atmos {

enum class NumberError { kNone, kSyntax, kRange, kNotFinite };

inline NumberError ParseNumber(std::string_view text, double* value) {
    if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+')
        text.remove_prefix(1);
    if (text.empty()) return NumberError::kSyntax;
    double v = 0.0;
    const auto result = std::from_chars(text.data(), text.data() + text.size(), v);
    if (result.ec == std::errc::result_out_of_range && result.ptr == text.data() + text.size()) {
        return NumberError::kRange;
    }
    if (result.ec != std::errc() || result.ptr != text.data() + text.size()) {
        return NumberError::kSyntax;
    }
    if (!std::isfinite(v)) return NumberError::kNotFinite;
    *value = v;
    return NumberError::kNone;
}

// " is not a number" and the like, to follow the quoted text in a message.
inline const char* NumberErrorText(NumberError e) {
    switch (e) {
        case NumberError::kNone:
            return "";
        case NumberError::kSyntax:
            return "is not a number";
        case NumberError::kRange:
            return "is out of the range of a double";
        case NumberError::kNotFinite:
            return "is not a finite number";
    }
    return "is not a number";
}

}  // namespace atmos
