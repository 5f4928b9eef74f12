// atmos: a progress bar with ETA on stderr for long work.
//
// Silent when disabled (--quiet), when stderr is not a terminal, and for work
// that finishes within about a second; the environment variable
// ATMOS_PROGRESS=1 draws every enabled bar anyway (from the start, whatever
// stderr is, always with its final line: logs and tests). Thread-safe: Add()
// may be called from worker threads.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "base/non_copyable.h"

namespace atmos {

class Progress : private NonCopyable {
  public:
    Progress(std::string label, int64_t total, bool enabled);
    ~Progress();

    void Add(int64_t done);
    // True when the bar can ever print (enabled and stderr is a terminal).
    bool active() const { return active_; }

    // Formats seconds as "1h02m", "3m05s" or "4.2s".
    static std::string FormatDuration(double seconds);

  private:
    void Draw(bool final_line);

    std::string label_;
    int64_t total_;
    bool active_;
    bool forced_;  // ATMOS_PROGRESS=1
    bool drawn_ = false;
    std::atomic<int64_t> done_{0};
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_;
    std::mutex mutex_;
};

}  // namespace atmos
