// Issue 38 items 1 and 5, issue 39 item 2: outputs written safely.
// Temporary files are created exclusively (a symbolic link planted under the
// names atmos used to predict can no longer redirect a write), outputs that
// are streams are written to and never replaced, other non-files are refused,
// a symbolic link is written through, two runs on one checkpoint fail fast,
// and paths are checked before the work with no directory created.
//
// ATMOS_TEST_CLI=PATH runs these against another atmos executable (to watch
// them fail on a build without the fixes).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "io/output_path.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

std::string Cli() {
    const char* env = std::getenv("ATMOS_TEST_CLI");
    return env ? env : ATMOS_CLI_PATH;
}

using atmos_test::Slurp;
using Outcome = atmos_test::CommandOutcome;

fs::path Dir(const std::string& name) {
    return atmos_test::FreshTestTmpDir("safe_output_" + name + "_" + std::to_string(getpid()));
}

// `sh -c SCRIPT` in `dir` with $ATMOS the executable; stdout and stderr kept.
Outcome Shell(const fs::path& dir, const std::string& script) {
    return atmos_test::RunCapturing(
        "cd '" + dir.string() + "' && ATMOS='" + Cli() + "' sh -c '" + script + "'",
        dir / "stdout.txt", dir / "stderr.txt");
}

const char kQueries[] = "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.5,0\n";

void WriteQueries(const fs::path& dir) { std::ofstream(dir / "q.csv") << kQueries; }

// The temporary beside an output was ".NAME.tmp-PID.EXT" and the write probe
// ".atmos-write-probe-PID": `exec` keeps the shell's PID, so links planted
// under those names for $$ are the names the old atmos opened (and followed).
TEST(SafeOutput, PlantedLinksAtOldTemporaryNamesRedirectNothing) {
    const fs::path dir = Dir("planted");
    WriteQueries(dir);
    std::ofstream(dir / "victim1") << "precious 1\n";
    std::ofstream(dir / "victim2") << "precious 2\n";
    const Outcome r =
        Shell(dir,
              "ln -s victim1 .out.csv.tmp-$$.csv && ln -s victim2 .atmos-write-probe-$$ && exec "
              "$ATMOS sample --model flat -o out.csv < q.csv");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(Slurp(dir / "victim1"), "precious 1\n");
    EXPECT_EQ(Slurp(dir / "victim2"), "precious 2\n");
    EXPECT_NE(Slurp(dir / "out.csv").find("altitude_m"), std::string::npos);
    fs::remove_all(dir);
}

// The checkpoint's temporary was the fixed STEM.bin.tmp.
TEST(SafeOutput, PlantedLinkAtOldCheckpointTemporaryRedirectsNothing) {
    const fs::path dir = Dir("ckpt_link");
    std::ofstream(dir / "victim") << "precious\n";
    fs::create_symlink("victim", dir / "ck.bin.tmp");
    const Outcome r = Shell(dir,
                            "$ATMOS render --model reference --size 4x2 --spp 2 --quiet "
                            "--checkpoint ck --keep-checkpoint -o r.exr");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(Slurp(dir / "victim"), "precious\n");
    EXPECT_TRUE(fs::is_regular_file(dir / "ck.bin"));
    // No temporary or lock is left behind.
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        EXPECT_EQ(name.find(".tmp-"), std::string::npos) << name;
        EXPECT_EQ(name.find(".lock"), std::string::npos) << name;
    }
    fs::remove_all(dir);
}

// Temporaries get the mode 0666 less the umask, as a file the shell creates.
TEST(SafeOutput, OutputModeFollowsTheUmask) {
    const fs::path dir = Dir("umask");
    WriteQueries(dir);
    const Outcome r = Shell(dir, "umask 027 && $ATMOS sample --model flat -o out.csv < q.csv");
    ASSERT_EQ(r.status, 0) << r.err;
    struct stat st {};
    ASSERT_EQ(::stat((dir / "out.csv").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0640u);
    fs::remove_all(dir);
}

// Streams are written to, never replaced: /dev/null stays a device, stdout
// gets the bytes ("-" and /dev/stdout, also when stdout is a file), a FIFO's
// reader gets them.
// /dev/null as a character device, or a skip: on a machine where another
// program (as root) has replaced it by a file there is nothing to test.
bool DevNullIsADevice() {
    struct stat st {};
    return ::stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode);
}

TEST(SafeOutput, StreamsAreWrittenToNotReplaced) {
    if (!DevNullIsADevice()) GTEST_SKIP() << "/dev/null is not a device here";
    const fs::path dir = Dir("streams");
    WriteQueries(dir);
    Outcome r = Shell(dir, "$ATMOS sample --model flat -o /dev/null < q.csv");
    EXPECT_EQ(r.status, 0) << r.err;
    struct stat st {};
    ASSERT_EQ(::stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null was replaced";
    const std::string expected = Shell(dir, "$ATMOS sample --model flat < q.csv").out;
    ASSERT_NE(expected.find("altitude_m"), std::string::npos);
    r = Shell(dir, "$ATMOS sample --model flat -o /dev/stdout < q.csv");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, expected);
    r = Shell(dir, "$ATMOS sample --model flat -o - < q.csv");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, expected);
    // A FIFO: its reader gets the CSV; it is still a FIFO.
    ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
    r = Shell(dir,
              "cat fifo > from_fifo.csv & $ATMOS sample --model flat -o fifo < q.csv; s=$?; wait; "
              "exit $s");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(Slurp(dir / "from_fifo.csv"), expected);
    ASSERT_EQ(::lstat((dir / "fifo").c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced";
    fs::remove_all(dir);
}

// A directory, another device: one error line, exit 2, nothing replaced.
TEST(SafeOutput, OtherNonFilesAreRefused) {
    const fs::path dir = Dir("refused");
    WriteQueries(dir);
    fs::create_directories(dir / "adir.csv");
    Outcome r = Shell(dir, "$ATMOS sample --model flat -o adir.csv < q.csv");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_directory(dir / "adir.csv"));
    r = Shell(dir, "$ATMOS sample --model flat -o /dev/zero < q.csv");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("is a device"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    struct stat st {};
    ASSERT_EQ(::stat("/dev/zero", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
    fs::remove_all(dir);
}

// A symbolic link is written through: its target gets the new bytes and the
// link stays a link; a dangling link is refused.
TEST(SafeOutput, SymlinkedOutputsAreWrittenThrough) {
    const fs::path dir = Dir("symlink");
    WriteQueries(dir);
    fs::create_directories(dir / "real");
    std::ofstream(dir / "real" / "target.csv") << "old\n";
    fs::create_symlink("real/target.csv", dir / "link.csv");
    Outcome r = Shell(dir, "$ATMOS sample --model flat -o link.csv < q.csv");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::is_symlink(dir / "link.csv"));
    EXPECT_NE(Slurp(dir / "real" / "target.csv").find("altitude_m"), std::string::npos);
    fs::create_symlink("real/none.csv", dir / "dangling.csv");
    r = Shell(dir, "$ATMOS sample --model flat -o dangling.csv < q.csv");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("symbolic link to a missing file"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "real" / "none.csv"));
    EXPECT_TRUE(fs::is_symlink(dir / "dangling.csv"));
    fs::remove_all(dir);
}

// `bench -o /dev/null` wrote its stages CSV to /dev/null_stages.csv.
TEST(SafeOutput, BenchToDevNullWritesNoSibling) {
    if (!DevNullIsADevice()) GTEST_SKIP() << "/dev/null is not a device here";
    const fs::path dir = Dir("bench");
    std::error_code ec;
    const bool before = fs::exists("/dev/null_stages.csv", ec);
    const Outcome r = Shell(dir,
                            "$ATMOS bench --models flat --views ground-noon --size 8x4 --repeat 1 "
                            "--warmup 0 -o /dev/null");
    EXPECT_EQ(r.status, 0) << r.err;
    if (!before) {
        EXPECT_FALSE(fs::exists("/dev/null_stages.csv", ec));
        fs::remove("/dev/null_stages.csv", ec);
    }
    struct stat st {};
    ASSERT_EQ(::stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
    fs::remove_all(dir);
}

// Two runs on one checkpoint: the second fails at once, before any pass, with
// one line naming the lock (here the first run is this test, holding it).
TEST(SafeOutput, SecondRunOnOneCheckpointFailsFast) {
    const fs::path dir = Dir("lock");
    const std::string stem = (dir / "ck").string();
    Outcome r;
    {
        const atmos::FileLock held(stem + ".bin");
        const auto start = std::chrono::steady_clock::now();
        r = Shell(dir,
                  "$ATMOS render --model reference --size 64x32 --spp 64 --quiet "
                  "--checkpoint ck -o r.exr");
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_LT(seconds, 10.0);
    }
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("another atmos run is using"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir / "r.exr"));
    EXPECT_FALSE(fs::exists(dir / "ck.bin.lock"));  // released and removed
    // Released: the same render now runs.
    r = Shell(dir,
              "$ATMOS render --model reference --size 8x4 --spp 2 --quiet --checkpoint ck "
              "-o r.exr");
    EXPECT_EQ(r.status, 0) << r.err;
    fs::remove_all(dir);
}

// Issue 39 item 2: a checkpoint in a missing directory fails before the work
// and creates nothing (it created the whole path); `sample -o` is checked
// before the queries are read.
TEST(SafeOutput, PathsCheckedBeforeWorkAndNoDirectoryCreated) {
    const fs::path dir = Dir("paths");
    Outcome r = Shell(dir,
                      "$ATMOS render --model reference --size 8x4 --spp 2 --quiet "
                      "--checkpoint missing/deeper/ck -o r.exr");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("missing/deeper/ck.bin"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "missing"));
    EXPECT_FALSE(fs::exists(dir / "r.exr"));
    // The queries on stdin are empty ("no input"): the output is named first.
    r = Shell(dir, "$ATMOS sample --model flat -o missing/x.csv < /dev/null");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("missing/x.csv"), std::string::npos) << r.err;
    fs::remove_all(dir);
}

}  // namespace

namespace {

// Issue 38 item 2: a directory written as one transaction. Uncommitted (a
// failure, an interruption), the previous directory is as it was and the
// staging sibling is gone; committed, the new contents replace the old
// entirely (no file of the previous bake survives to make a mix).
TEST(SafeOutput, StagedDirectoryIsOneTransaction) {
    const fs::path dir = Dir("staged");
    const fs::path bake = dir / "bake";
    fs::create_directories(bake);
    std::ofstream(bake / "table.exr") << "old table\n";
    std::ofstream(bake / "stale.exr") << "old only\n";
    try {
        atmos::StagedDirectory staged(bake.string());
        std::ofstream(fs::path(staged.path()) / "table.exr") << "new table\n";
        throw std::runtime_error("interrupted");
    } catch (const std::runtime_error&) {
    }
    EXPECT_EQ(Slurp(bake / "table.exr"), "old table\n");
    EXPECT_EQ(Slurp(bake / "stale.exr"), "old only\n");
    {
        atmos::StagedDirectory staged(bake.string());
        std::ofstream(fs::path(staged.path()) / "table.exr") << "new table\n";
        staged.Commit();
    }
    EXPECT_EQ(Slurp(bake / "table.exr"), "new table\n");
    EXPECT_FALSE(fs::exists(bake / "stale.exr"));
    // Nothing but the bake is left beside it.
    int entries = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        ++entries;
        EXPECT_EQ(e.path().filename(), "bake");
    }
    EXPECT_EQ(entries, 1);
    fs::remove_all(dir);
}

// `bake` over an older bake replaces it as a whole: a table only the older
// one had does not survive into a mix (`render --load` accepted a mix).
TEST(SafeOutput, BakeReplacesTheWholeDirectory) {
    const fs::path dir = Dir("bake");
    fs::create_directories(dir / "b");
    std::ofstream(dir / "b" / "scattering.exr") << "a table of another bake\n";
    const Outcome r = Shell(dir, "$ATMOS bake --model hillaire --quiet -o b");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(fs::exists(dir / "b" / "scattering.exr"));
    EXPECT_FALSE(fs::is_empty(dir / "b"));
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        EXPECT_EQ(e.path().filename().string().find(".new-"), std::string::npos) << e.path();
    }
    // A directory of other files is refused before the work, left as it was.
    fs::create_directories(dir / "mine");
    std::ofstream(dir / "mine" / "notes.txt") << "mine\n";
    const Outcome refused = Shell(dir, "$ATMOS bake --model hillaire --quiet -o mine");
    EXPECT_EQ(refused.status, 2) << refused.err;
    EXPECT_NE(refused.err.find("which atmos does not write"), std::string::npos) << refused.err;
    EXPECT_EQ(Slurp(dir / "mine" / "notes.txt"), "mine\n");
    fs::remove_all(dir);
}

}  // namespace
