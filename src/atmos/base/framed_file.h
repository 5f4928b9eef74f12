// atmos: the framed binary files of checkpoints (render/progressive.cpp) and
// shards (render/shards.cpp): an 8-byte magic, the JSON header's size (a
// uint64 in the machine's byte order), the header, the body (float images) and
// the 64-bit FNV-1a of everything before it.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "base/fnv1a.h"

namespace atmos {

// The bytes a frame adds around its header and body.
constexpr std::size_t kFrameOverhead = 8 + 8 + 8;

// A frame's start (magic, header size, header), with room for `body_bytes`.
inline std::string BeginFrame(const char (&magic)[8], const std::string& header,
                              std::size_t body_bytes = 0) {
    std::string bytes;
    bytes.reserve(kFrameOverhead + header.size() + body_bytes);
    bytes.append(magic, sizeof magic);
    const std::uint64_t header_size = header.size();
    bytes.append(reinterpret_cast<const char*>(&header_size), sizeof header_size);
    bytes.append(header);
    return bytes;
}

// Appends the checksum that ends a frame.
inline void EndFrame(std::string* bytes) {
    const std::uint64_t checksum = Fnv1a(bytes->data(), bytes->size());
    bytes->append(reinterpret_cast<const char*>(&checksum), sizeof checksum);
}

// What CheckFrame says about each way a frame can be broken.
struct FrameMessages {
    const char* no_magic;
    const char* truncated_header;
    const char* checksum;
};

// The header's size of the frame `bytes` (its header at offset 16, the body
// after it); calls fail(message) (which must throw) when the magic is not
// `magic`, the header runs past the end or the checksum does not hold.
template <typename FailFn>
std::uint64_t CheckFrame(const std::string& bytes, const char (&magic)[8],
                         const FrameMessages& messages, FailFn&& fail) {
    if (bytes.size() < kFrameOverhead || bytes.compare(0, sizeof magic, magic, sizeof magic) != 0) {
        fail(messages.no_magic);
    }
    std::uint64_t header_size = 0, checksum = 0;
    std::memcpy(&header_size, bytes.data() + 8, sizeof header_size);
    std::memcpy(&checksum, bytes.data() + bytes.size() - 8, sizeof checksum);
    if (header_size > bytes.size() - kFrameOverhead) fail(messages.truncated_header);
    if (Fnv1a(bytes.data(), bytes.size() - 8) != checksum) fail(messages.checksum);
    return header_size;
}

}  // namespace atmos
