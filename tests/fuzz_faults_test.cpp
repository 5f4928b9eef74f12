// Issue 38 item 5: the audit's I/O fault injections, a full disk (ENOSPC) and
// a read-only directory (EROFS), during every kind of output: images (EXR,
// PNG, PFM, NPY), CSV/JSON reports (sample, bench, validate, fit, compare),
// merge and flip outputs, the checkpoint, bake and viewer directories, the
// render cache and the table cache. Each failure must be one
// "atmos: error:" line naming the path and the reason with exit status 2,
// and leave no temporary or truncated file and any previous output as it
// was; a cache that cannot be written costs a warning, not the run.
//
// The faults come from tests/fuzz_fault_shim.cpp, preloaded into `atmos`
// (LD_PRELOAD): tests run as root on CI, where chmod makes nothing
// read-only, and a container may not allow a small tmpfs. Under AddressSanitizer
// these tests are skipped: ASan must be the first library loaded, and a
// preloaded shim ahead of it is refused; they run in the Release build (the
// first half of .ci/run, `scripts/test.sh`).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "test_util.h"

namespace fs = std::filesystem;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

#define SKIP_UNDER_SANITIZER()                                                                    \
    if (kSanitized) {                                                                             \
        GTEST_SKIP() << "LD_PRELOAD of the fault shim ahead of ASan's runtime is refused; these " \
                        "run in the Release build";                                               \
    }

using atmos_test::Slurp;

// ATMOS_TEST_CLI=PATH runs these against another atmos executable (to watch
// them fail on a build without the fixes).
std::string Cli() {
    const char* env = std::getenv("ATMOS_TEST_CLI");
    return env ? env : ATMOS_CLI_PATH;
}

struct Fault {
    std::string where;  // a path prefix under the case's directory ("" : all of it)
    std::string error = "ENOSPC";
    std::string ops = "write";
    long long after = 0;
};

struct Outcome {
    int status = -1;
    std::string err;
    int faults = 0;  // faults the shim injected
};

// A case's folder: `work` (the command's directory) and the shim's log beside it.
struct Case {
    fs::path root, work;
    explicit Case(const std::string& name) {
        root = atmos_test::FreshTestTmpDir("fuzz_faults_" + name + "_" + std::to_string(getpid()));
        work = root / "work";
        fs::create_directories(work);
        root = fs::canonical(root);
        work = fs::canonical(work);
        std::ofstream(work / "q.csv") << "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.5,0\n"
                                      << "1000,0.1,0.2,90\n";
    }
    ~Case() {
        std::error_code ec;
        fs::remove_all(root, ec);
    }

    // `atmos ARGS` in `work`, with the fault when given (and `env`).
    Outcome Run(const std::string& args, const Fault* fault = nullptr,
                const std::string& env = "") const {
        const fs::path log = root / "fault.log";
        fs::remove(log);
        std::string cmd = "cd '" + work.string() + "' && env ATMOS_NO_CACHE=1 " + env + " ";
        if (fault) {
            cmd += std::string("LD_PRELOAD='") + ATMOS_FAULT_SHIM_PATH + "' ATMOS_FAULT_PATH='" +
                   work.string() + "/" + fault->where + "' ATMOS_FAULT_ERRNO=" + fault->error +
                   " ATMOS_FAULT_OPS=" + fault->ops +
                   " ATMOS_FAULT_AFTER=" + std::to_string(fault->after) + " ATMOS_FAULT_LOG='" +
                   log.string() + "' ";
        }
        cmd += Cli() + " " + args + " < /dev/null";
        const atmos_test::CommandOutcome r =
            atmos_test::RunCapturing(cmd, root / "stdout.txt", root / "stderr.txt");
        Outcome o;
        o.status = r.status;
        o.err = r.err;
        const std::string text = Slurp(log);
        o.faults = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
        return o;
    }

    // Every file and folder under `work`: relative path -> bytes ("/" for a folder).
    std::map<std::string, std::string> Snapshot() const {
        std::map<std::string, std::string> files;
        for (const auto& e : fs::recursive_directory_iterator(work)) {
            const std::string name = fs::relative(e.path(), work).string();
            files[name] = e.is_directory() ? "/" : Slurp(e.path());
        }
        return files;
    }

    // Names under `work` that are temporaries (".NAME.tmp-", ".NAME.new-").
    std::vector<std::string> Temporaries() const {
        std::vector<std::string> found;
        for (const auto& e : fs::recursive_directory_iterator(work)) {
            const std::string name = e.path().filename().string();
            const bool ends_tmp = name.size() >= 4 && name.compare(name.size() - 4, 4, ".tmp") == 0;
            if (name.find(".tmp-") != std::string::npos ||
                name.find(".new-") != std::string::npos || ends_tmp) {
                found.push_back(fs::relative(e.path(), work).string());
            }
        }
        return found;
    }
};

const char* Reason(const std::string& error) {
    return std::strerror(error == "EROFS" ? EROFS : error == "EACCES" ? EACCES : ENOSPC);
}

// One "atmos: error:" line naming `path` and the fault's reason, status 2,
// the fault reached.
void ExpectOneLineFailure(const Outcome& r, const std::string& path, const Fault& fault,
                          const std::string& what) {
    EXPECT_EQ(r.status, 2) << what << "\n" << r.err;
    EXPECT_GE(r.faults, 1) << what << ": the fault was never reached";
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("atmos: error: ", 0), 0u) << what << "\n" << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << what << ": no '" << path << "'\n" << r.err;
    EXPECT_NE(r.err.find(Reason(fault.error)), std::string::npos)
        << what << ": no '" << Reason(fault.error) << "'\n"
        << r.err;
}

void ExpectUnchanged(const std::map<std::string, std::string>& before,
                     const std::map<std::string, std::string>& after, const std::string& what) {
    for (const auto& [name, bytes] : after) {
        const auto it = before.find(name);
        EXPECT_TRUE(it != before.end()) << what << ": left '" << name << "' behind";
        if (it != before.end()) {
            EXPECT_TRUE(it->second == bytes) << what << ": changed '" << name << "'";
        }
    }
    for (const auto& [name, bytes] : before) {
        EXPECT_TRUE(after.count(name)) << what << ": removed '" << name << "'";
    }
}

// The faults every output meets: a disk full from the first byte, one full
// after a few bytes (the header written), one that fails the close (as NFS
// reports it), and a read-only directory.
std::vector<Fault> OutputFaults() {
    std::vector<Fault> faults(4);
    faults[1].after = 97;
    faults[2].ops = "close";
    faults[3].error = "EROFS";
    faults[3].ops = "all";
    return faults;
}

std::string Describe(const std::string& args, const Fault& f) {
    return args + " [" + f.error + " on " + f.ops + " after " + std::to_string(f.after) + "]";
}

// A single-file output, with and without a previous one: each fault fails
// the command in one line and leaves the folder exactly as it was.
void CheckFileOutput(const std::string& name, const std::string& args, const std::string& output,
                     const std::string& prepare = "") {
    Case c(name);
    if (!prepare.empty()) {
        ASSERT_EQ(c.Run(prepare).status, 0) << prepare;
    }
    for (const bool previous : {false, true}) {
        if (previous) {
            const Outcome first = c.Run(args);
            ASSERT_EQ(first.status, 0) << args << "\n" << first.err;
            ASSERT_TRUE(fs::exists(c.work / output)) << args;
        }
        for (const Fault& fault : OutputFaults()) {
            const auto before = c.Snapshot();
            const Outcome r = c.Run(args, &fault);
            const std::string what = Describe(args, fault) + (previous ? " over a previous" : "");
            ExpectOneLineFailure(r, output, fault, what);
            ExpectUnchanged(before, c.Snapshot(), what);
        }
    }
}

TEST(FuzzFaults, ImagesFailInOneLineAndLeaveNoFile) {
    SKIP_UNDER_SANITIZER();
    for (const char* ext : {"exr", "png", "pfm", "npy"}) {
        const std::string out = std::string("sky.") + ext;
        CheckFileOutput(std::string("image_") + ext,
                        "render --model preetham --size 16x8 -q -o " + out, out);
    }
}

TEST(FuzzFaults, ReportsFailInOneLineAndLeaveNoFile) {
    SKIP_UNDER_SANITIZER();
    CheckFileOutput("sample", "sample --model flat -i q.csv -o out.csv", "out.csv");
    CheckFileOutput("sample_spectral",
                    "sample --model naive --wavelengths 440:680:3 -i q.csv -o out.csv", "out.csv");
    CheckFileOutput("bench",
                    "bench --models flat --views ground-noon --size 16x8 -n 1 --warmup 0 -o b.csv",
                    "b.csv");
    const std::string kider = std::string(ATMOS_TEST_DATA) + "/kider-2013";
    CheckFileOutput(
        "validate",
        "validate kider-2013 -q --models flat --captures 09:30 --data " + kider + " -o v.csv",
        "v.csv");
    CheckFileOutput("fit",
                    "fit --model neural --reference flat --transmittance-samples 64 "
                    "--scattering-samples 64 --transmittance-iterations 2 "
                    "--scattering-iterations 2 -q -o w.json",
                    "w.json");
}

TEST(FuzzFaults, MergeAndFlipOutputsFailInOneLine) {
    SKIP_UNDER_SANITIZER();
    const std::string shards =
        "render --model reference --size 8x4 --spp 4 -q --shard 1/2 -o p1.shard && " + Cli() +
        " render --model reference --size 8x4 --spp 4 -q --shard 2/2 -o p2.shard";
    CheckFileOutput("merge", "merge -q p1.shard p2.shard -o m.exr", "m.exr", shards);
    const std::string images = "render --model flat --size 16x8 -q -o a.exr && " + Cli() +
                               " render --model preetham --size 16x8 -q -o b.exr";
    CheckFileOutput("flip_exr", "flip a.exr b.exr -o f.exr", "f.exr", images);
    CheckFileOutput("flip_png", "flip a.exr b.exr -o f.png", "f.png", images);
}

// The checkpoint (in its own folder, where the faults are): the render fails
// in one line, no temporary beside the checkpoint, no image written.
TEST(FuzzFaults, CheckpointWriteFailsInOneLine) {
    SKIP_UNDER_SANITIZER();
    Case c("checkpoint");
    fs::create_directories(c.work / "ck");
    const std::string args =
        "render --model reference --size 8x4 --spp 8 --pass-spp 1 -q --checkpoint ck/run -o x.exr";
    std::vector<Fault> faults = OutputFaults();
    Fault fsync_fault, rename_fault;
    fsync_fault.ops = "fsync";
    rename_fault.ops = "rename";
    faults.push_back(fsync_fault);
    faults.push_back(rename_fault);
    for (Fault fault : faults) {
        fault.where = "ck/";
        const auto before = c.Snapshot();
        const Outcome r = c.Run(args, &fault);
        const std::string what = Describe(args, fault);
        ExpectOneLineFailure(r, "ck/run", fault, what);
        ExpectUnchanged(before, c.Snapshot(), what);
    }
    // Without the fault the same render completes.
    const Outcome ok = c.Run(args);
    EXPECT_EQ(ok.status, 0) << ok.err;
    EXPECT_TRUE(fs::exists(c.work / "x.exr"));
}

// bake and viewer: a previous directory stays byte for byte, no staging
// folder is left, and the message names the output directory.
TEST(FuzzFaults, BakeAndViewerLeaveThePreviousDirectory) {
    SKIP_UNDER_SANITIZER();
    for (const std::string args : {"bake --model hillaire -q -o out",
                                   "viewer --models hillaire "
                                   "-q -o out"}) {
        Case c(args.substr(0, 4));
        for (const bool previous : {false, true}) {
            if (previous) {
                ASSERT_EQ(c.Run(args).status, 0) << args;
            }
            std::vector<Fault> faults = OutputFaults();
            faults[1].after = 150000;  // inside the tables
            Fault rename_fault;
            rename_fault.ops = "rename";
            faults.push_back(rename_fault);
            for (const Fault& fault : faults) {
                const auto before = c.Snapshot();
                const Outcome r = c.Run(args, &fault);
                const std::string what =
                    Describe(args, fault) + (previous ? " over a previous" : "");
                ExpectOneLineFailure(r, "out", fault, what);
                EXPECT_EQ(r.err.find(".new-"), std::string::npos)
                    << what << ": names the staging folder\n"
                    << r.err;
                ExpectUnchanged(before, c.Snapshot(), what);
            }
        }
    }
}

// compare writes many files into its folder: each failure is one line and
// leaves no temporary (every file there is whole).
TEST(FuzzFaults, CompareFailsInOneLineAndLeavesNoTemporary) {
    SKIP_UNDER_SANITIZER();
    Case c("compare");
    const std::string args =
        "compare --models flat --views ground-noon --size 16x8 --reference-spp 2 --no-cache -q "
        "-o cmp";
    for (Fault fault : OutputFaults()) {
        fault.after = fault.after > 0 ? 5000 : 0;
        const Outcome r = c.Run(args, &fault);
        const std::string what = Describe(args, fault);
        ExpectOneLineFailure(r, "cmp", fault, what);
        EXPECT_TRUE(c.Temporaries().empty()) << what << ": " << c.Temporaries().front();
    }
}

// A render cache that cannot be written: the comparison completes with one
// warning, and no partial entry is left (an image without its JSON).
TEST(FuzzFaults, RenderCacheFailureWarnsAndCompletes) {
    SKIP_UNDER_SANITIZER();
    Case c("render_cache");
    const std::string args =
        "compare --models flat --views ground-noon --size 16x8 --reference-spp 2 -q --cache rc "
        "-o cmp";
    fs::create_directories(c.work / "rc");
    for (Fault fault : OutputFaults()) {
        fault.where = "rc/";
        if (fault.after > 0) fault.after = 700;  // after the first entry's image has started
        fs::remove_all(c.work / "cmp");
        const Outcome r = c.Run(args, &fault);
        const std::string what = Describe(args, fault);
        EXPECT_EQ(r.status, 0) << what << "\n" << r.err;
        EXPECT_GE(r.faults, 1) << what;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("atmos: warning: render cache: cannot store in", 0), 0u)
            << what << "\n"
            << r.err;
        EXPECT_TRUE(fs::exists(c.work / "cmp" / "flip.csv")) << what;
        for (const auto& e : fs::directory_iterator(c.work / "rc")) {
            const fs::path p = e.path();
            if (p.extension() == ".exr" && p.string().find(".variance.exr") == std::string::npos) {
                EXPECT_TRUE(fs::exists(fs::path(p).replace_extension(".json")))
                    << what << ": partial entry " << p;
            }
            EXPECT_EQ(p.filename().string().find(".tmp-"), std::string::npos) << what << p;
        }
    }
}

// A table cache that cannot be written: the render completes with one
// warning and no entry (nor temporary) is stored, whichever write fails (the
// tables or the manifest, written last).
TEST(FuzzFaults, TableCacheFailureWarnsAndStoresNothing) {
    SKIP_UNDER_SANITIZER();
    Case c("table_cache");
    const std::string env = "ATMOS_NO_CACHE= XDG_CACHE_HOME='" + (c.work / "xdg").string() + "'";
    const std::string args = "render --model hillaire --size 16x8 -q -o sky.exr";
    // The bytes of one entry's tables, without its manifest (the budget that
    // lets the tables through and fails the manifest).
    ASSERT_EQ(c.Run(args, nullptr, env).status, 0);
    long long tables = 0;
    for (const auto& e : fs::recursive_directory_iterator(c.work / "xdg")) {
        if (e.is_regular_file() && e.path().filename() != "manifest.json") {
            tables += static_cast<long long>(e.file_size());
        }
    }
    ASSERT_GT(tables, 0);
    std::vector<Fault> faults = OutputFaults();
    faults[1].after = tables;  // the manifest fails
    Fault inside;
    inside.after = tables / 2;
    faults.push_back(inside);
    for (Fault fault : faults) {
        fault.where = "xdg/";
        fs::remove_all(c.work / "xdg");
        fs::create_directories(c.work / "xdg");
        fs::remove(c.work / "sky.exr");
        const Outcome r = c.Run(args, &fault, env);
        const std::string what = Describe(args, fault);
        EXPECT_EQ(r.status, 0) << what << "\n" << r.err;
        EXPECT_GE(r.faults, 1) << what;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("atmos: warning: table cache: cannot store", 0), 0u) << what << "\n"
                                                                                   << r.err;
        EXPECT_NE(r.err.find(Reason(fault.error)), std::string::npos) << what << "\n" << r.err;
        EXPECT_TRUE(fs::exists(c.work / "sky.exr")) << what;
        for (const auto& e : fs::recursive_directory_iterator(c.work / "xdg")) {
            EXPECT_TRUE(e.is_directory()) << what << ": left " << e.path();
        }
    }
}

}  // namespace
