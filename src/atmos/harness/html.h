// atmos: HTML text escaping for the pages the harness writes.
#pragma once

#include <string>

namespace atmos {

// Escapes &, <, > and " so `s` can stand in element text and quoted attributes.
inline std::string HtmlEscape(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

}  // namespace atmos
