// atmos: inputs read with bounds (issue 38 item 6).
//
// Every input is read with a limit on its size, and text with a limit on its
// line length, checked as it is read: /dev/zero, a FIFO that never ends or a
// 1 GB line is one clear atmos::Error after at most the limit, never memory
// that grows until the process is killed. Directories are refused.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace atmos {

// Limits (bytes): query CSVs and NPYs, image files, `loc` sources.
constexpr size_t kMaxQueryInputBytes = size_t{2} << 30;   // 2 GiB: ~40 million queries
constexpr size_t kMaxCsvLineBytes = 4096;                 // a query line holds 4 numbers
constexpr size_t kMaxImageFileBytes = size_t{4} << 30;    // 4 GiB
constexpr size_t kMaxSourceFileBytes = size_t{64} << 20;  // 64 MiB: a source file
// Images: at most 2^27 pixels (16384 x 8192; 1.5 GiB of floats) and 65535 a side.
constexpr int64_t kMaxImagePixels = int64_t{1} << 27;
constexpr int kMaxImageSide = 65535;

// The bytes of `file` (already open; `what` names it in messages), at most
// `max_bytes`, and when `max_line` > 0 no line longer than `max_line` bytes.
std::string ReadBounded(std::FILE* file, const std::string& what, size_t max_bytes,
                        size_t max_line = 0);
// The same for the file `path` (a directory is refused). A FIFO is opened
// without blocking and must deliver within ATMOS_INPUT_WAIT_SECONDS (10 s by
// default), else one atmos::Error: a FIFO that no one writes never hangs.
std::string ReadFileBounded(const std::string& path, size_t max_bytes, size_t max_line = 0);

// One atmos::Error when `path` exists and is not a regular file (a FIFO, a
// device, a socket), for readers that open by name and would block on a FIFO
// no one writes or read a device without end (EXR, PNG, neural weights);
// `what` names the input. A missing path passes (the reader names it).
void RequireRegularInput(const std::string& path, const std::string& what);

// One atmos::Error unless width x height is an image atmos reads (the limits
// above), before anything is allocated for it; `what` names the file.
void CheckImageDimensions(int64_t width, int64_t height, const std::string& what);

}  // namespace atmos
