// atmos tests: what several test files share (temporary folders, reading a
// file, running a command or the `atmos` executable, spawning a render with
// the stop signals at their default action).
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "base/parallel.h"
#include "render/stages.h"

extern char** environ;

namespace atmos_test {

// $ATMOS_TEST_TMP, else the system's temporary folder / atmos_test.
inline std::filesystem::path TestTmpRoot() {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    return env ? std::filesystem::path(env) : std::filesystem::temp_directory_path() / "atmos_test";
}

// TestTmpRoot() / `name`, created (what it holds is kept).
inline std::filesystem::path TestTmpDir(const std::string& name) {
    const std::filesystem::path dir = TestTmpRoot() / name;
    std::filesystem::create_directories(dir);
    return dir;
}

// TestTmpRoot() / `name`, emptied and created.
inline std::filesystem::path FreshTestTmpDir(const std::string& name) {
    const std::filesystem::path dir = TestTmpRoot() / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

// A file's bytes ("" when it cannot be read).
inline std::string Slurp(const std::filesystem::path& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

// Runs the shell command line `cmd`; its exit status, -1 when a signal ended it.
inline int System(const std::string& cmd) {
    const int raw = std::system(cmd.c_str());
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

struct CommandOutcome {
    int status = -1;  // exit status; -1: ended by a signal
    std::string out, err;
};

// Runs the shell command line `command` with stdout to `out` and stderr to
// `err` (both kept), and reads them back.
inline CommandOutcome RunCapturing(const std::string& command, const std::filesystem::path& out,
                                   const std::filesystem::path& err) {
    const std::string cmd = command + " > '" + out.string() + "' 2> '" + err.string() + "'";
    const int raw = std::system(cmd.c_str());
    CommandOutcome r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = Slurp(out);
    r.err = Slurp(err);
    return r;
}

// `atmos ARGS` with stdin from `input`, in `dir`'s files inID, outID, errID.
inline CommandOutcome RunAtmosWithInput(const std::filesystem::path& dir, const std::string& id,
                                        const std::string& args, const std::string& input) {
    const std::filesystem::path in = dir / ("in" + id);
    std::ofstream(in) << input;
    return RunCapturing(std::string(ATMOS_CLI_PATH) + " " + args + " < '" + in.string() + "'",
                        dir / ("out" + id), dir / ("err" + id));
}

// Spawns `argv[0]` with `argv` (stdout to /dev/null, stderr to `err_path`),
// no signal blocked and `signals` at their default action, whatever this
// process inherited (a CI may start the suite with SIGINT blocked or
// ignored). Returns posix_spawn's error (0: spawned, *pid set).
inline int SpawnWithDefaultSignals(std::vector<std::string> argv_text, const std::string& err_path,
                                   std::initializer_list<int> signals, pid_t* pid) {
    std::vector<char*> argv;
    for (std::string& w : argv_text) argv.push_back(w.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&files, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none, stops;
    sigemptyset(&none);
    sigemptyset(&stops);
    for (int s : signals) sigaddset(&stops, s);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &stops);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    const int spawned = posix_spawn(pid, argv[0], &files, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&files);
    posix_spawnattr_destroy(&attr);
    return spawned;
}

// Waits (no time limit: ctest's own bounds it), polling every `poll_us`, until
// process `pid` catches `signal` (its bit in SigCgt of /proc/PID/status) or
// has ended; true when it ended (its wait status in *raw).
inline bool WaitUntilCatching(pid_t pid, int signal, useconds_t poll_us, int* raw) {
    const std::string status_path = "/proc/" + std::to_string(pid) + "/status";
    bool catching = false, ended = false;
    while (!catching && !ended) {
        std::ifstream status(status_path);
        for (std::string line; std::getline(status, line);) {
            if (line.rfind("SigCgt:", 0) == 0) {
                catching = (std::stoull(line.substr(7), nullptr, 16) >> (signal - 1)) & 1u;
            }
        }
        if (!catching) {
            ended = waitpid(pid, raw, WNOHANG) == pid;
            if (!ended) usleep(poll_us);
        }
    }
    return ended;
}

// `model` renders `request` to the same bytes with 1 thread and with 2;
// returns the image.
inline atmos::Image ExpectSameImageForOneAndTwoThreads(const atmos::Model& model,
                                                       const atmos::RenderRequest& request) {
    atmos::Image one, two;
    {
        atmos::ThreadLimit limit(1);
        model.Render(request, &one);
    }
    {
        atmos::ThreadLimit limit(2);
        model.Render(request, &two);
    }
    EXPECT_EQ(one.size(), two.size());
    if (one.size() == two.size()) {
        EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
    }
    return one;
}

// True when every stage is trivially copyable and declared a device stage
// (ATMOS_DEVICE_STAGE, render/stages.h).
template <typename... Stages>
constexpr bool kAreDeviceStages =
    ((std::is_trivially_copyable<Stages>::value && atmos::HasDeviceStage<Stages>::value) && ...);

// The message of the atmos::Error `f` throws; "" when it throws none (a
// failure when `f` must throw) or another exception (always a failure).
template <typename F>
std::string ErrorOrEmpty(F f, bool must_throw = false) {
    try {
        f();
    } catch (const atmos::Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "threw a non-atmos exception: " << e.what();
        return "";
    }
    if (must_throw) ADD_FAILURE() << "did not throw";
    return "";
}

// Runs `f`, expects atmos::Error, and returns its message ("" if none was thrown).
template <typename F>
std::string ErrorMessage(F f) {
    return ErrorOrEmpty(f, true);
}

// The tables of a test stage (render/stages.h) that reads `in` and writes or
// accumulates into `out`; the stage adds its operator().
struct InOutStage {
    atmos::TableView in;
    atmos::TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        v(in);
        v(out);
    }
};

// A render request of `view` at width x height, without progress bars.
inline atmos::RenderRequest QuietRequest(const atmos::View& view, int width, int height) {
    atmos::RenderRequest request;
    request.view = view;
    request.width = width;
    request.height = height;
    request.show_progress = false;
    return request;
}

// QuietRequest for a Monte Carlo model: spp paths per pixel in passes of
// pass_spp from `seed`.
inline atmos::RenderRequest MonteCarloRequest(const atmos::View& view, int width, int height,
                                              int64_t spp, int64_t pass_spp, uint64_t seed) {
    atmos::RenderRequest request = QuietRequest(view, width, height);
    request.monte_carlo.spp = spp;
    request.monte_carlo.seed = seed;
    request.monte_carlo.pass_spp = pass_spp;
    return request;
}

}  // namespace atmos_test

// `statement` throws an atmos::Error whose message contains `text`.
#define EXPECT_ERROR_CONTAINS(statement, text)                                             \
    do {                                                                                   \
        const std::string message_ = atmos_test::ErrorMessage([&] { (void)(statement); }); \
        EXPECT_NE(message_.find(text), std::string::npos)                                  \
            << "message: \"" << message_ << "\" lacks \"" << (text) << "\"";               \
    } while (0)
