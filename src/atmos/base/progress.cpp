#include "base/progress.h"

#include "base/library_progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace atmos {

namespace {
std::atomic<bool> g_library_progress{false};
constexpr double kQuietSeconds = 1.0;   // show nothing for work shorter than this
constexpr double kRedrawSeconds = 0.1;  // at most 10 redraws a second

// ATMOS_PROGRESS=1: every enabled bar is drawn, from the start and whatever
// stderr is (logs, tests); its final line always.
bool ProgressForced() {
    const char* env = std::getenv("ATMOS_PROGRESS");
    return env != nullptr && std::strcmp(env, "1") == 0;
}

}  // namespace

bool LibraryProgressEnabled() { return g_library_progress.load(std::memory_order_relaxed); }

LibraryProgressScope::LibraryProgressScope(bool enabled)
    : previous_(g_library_progress.exchange(enabled)) {}

LibraryProgressScope::~LibraryProgressScope() { g_library_progress.store(previous_); }

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      active_(enabled && (isatty(STDERR_FILENO) != 0 || ProgressForced())),
      forced_(enabled && ProgressForced()),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
    if (drawn_ || forced_) Draw(true);
}

std::string Progress::FormatDuration(double seconds) {
    char buf[32];
    if (seconds < 0) seconds = 0;
    if (seconds >= 3600) {
        std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(seconds / 3600),
                      static_cast<int>(seconds / 60) % 60);
    } else if (seconds >= 60) {
        std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(seconds / 60),
                      static_cast<int>(seconds) % 60);
    } else {
        std::snprintf(buf, sizeof buf, "%.1fs", seconds);
    }
    return buf;
}

void Progress::Add(int64_t done) {
    done_.fetch_add(done, std::memory_order_relaxed);
    if (!active_) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double since_draw = std::chrono::duration<double>(now - last_draw_).count();
    if ((elapsed < kQuietSeconds && !forced_) || since_draw < kRedrawSeconds) return;
    last_draw_ = now;
    Draw(false);
}

void Progress::Draw(bool final_line) {
    const int64_t done = done_.load(std::memory_order_relaxed);
    const double fraction = done >= total_ ? 1.0 : static_cast<double>(done) / total_;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int width = 30;
    const int filled = static_cast<int>(fraction * width);
    std::string bar(static_cast<size_t>(filled), '#');
    bar.append(static_cast<size_t>(width - filled), '-');
    std::string eta = fraction > 0.0 && !final_line
                          ? "ETA " + FormatDuration(elapsed * (1.0 - fraction) / fraction)
                          : FormatDuration(elapsed);
    std::fprintf(stderr, "\r%s [%s] %5.1f%% %s  ", label_.c_str(), bar.c_str(), 100.0 * fraction,
                 eta.c_str());
    if (final_line) std::fputc('\n', stderr);
    std::fflush(stderr);
    drawn_ = true;
}

}  // namespace atmos
