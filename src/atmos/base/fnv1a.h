// atmos: the 64-bit FNV-1a hash (Fowler, Noll and Vo; offset basis
// 14695981039346656037, prime 1099511628211) of bytes and of a stream: the
// table and render caches' keys and checksums, the checkpoints' checksum.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <istream>
#include <string>

namespace atmos {

constexpr std::uint64_t kFnv1aOffsetBasis = 14695981039346656037ull;

// The hash of `size` bytes at `data`, continuing from `h`.
inline std::uint64_t Fnv1a(const char* data, std::size_t size,
                           std::uint64_t h = kFnv1aOffsetBasis) {
    for (std::size_t i = 0; i < size; ++i) {
        h ^= static_cast<unsigned char>(data[i]);
        h *= 1099511628211ull;
    }
    return h;
}

// `h` as 16 lowercase hexadecimal digits (the caches' keys and checksums).
inline std::string Fnv1aHex(std::uint64_t h) {
    char text[17];
    std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(h));
    return std::string(text);
}

// The hash of the bytes of `in` to its end; *bytes (optional) their count.
inline std::uint64_t Fnv1aStream(std::istream& in, std::int64_t* bytes = nullptr) {
    std::uint64_t h = kFnv1aOffsetBasis;
    std::int64_t total = 0;
    char buffer[1 << 16];
    while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) {
        const std::streamsize n = in.gcount();
        h = Fnv1a(buffer, static_cast<std::size_t>(n), h);
        total += n;
    }
    if (bytes) *bytes = total;
    return h;
}

}  // namespace atmos
