// atmos: the one error type of the host code.
//
// Every user-facing failure (bad option, unreadable file, invalid parameter)
// throws atmos::Error with one clear line; the executable prints it and exits
// non-zero. Per-pixel (ATMOS_HD) code never throws.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace atmos {

class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

namespace detail {
inline void AppendAll(std::ostringstream&) {}
template <typename T, typename... Rest>
void AppendAll(std::ostringstream& os, const T& first, const Rest&... rest) {
    os << first;
    AppendAll(os, rest...);
}
}  // namespace detail

// Throws atmos::Error with the arguments streamed into one message.
template <typename... Args>
[[noreturn]] void Fail(const Args&... args) {
    std::ostringstream os;
    detail::AppendAll(os, args...);
    throw Error(os.str());
}

}  // namespace atmos
