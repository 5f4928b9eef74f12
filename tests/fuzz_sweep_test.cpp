// Issue 38 item 5: the bad-input sweep as data, tests/data/fuzz/bad_inputs.tsv
// (expected exit status, message class, arguments): each case is one clear
// "atmos: error:" line with its status (or a success), nothing written beside
// it, no hang (every case ends: a FIFO, /dev/zero and oversized inputs
// included), and /dev/null, /dev/zero stay devices. Part of the `fuzz` ctest
// label (`scripts/test.sh --integration`); the counts are printed.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::string Slurp(const fs::path& p) {
    std::ifstream f(p);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

bool IsCharDevice(const char* path) {
    struct stat st {};
    return ::stat(path, &st) == 0 && S_ISCHR(st.st_mode);
}

TEST(FuzzSweep, BadInputsFromDataGiveOneLineAndTheirStatus) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    const fs::path dir = (env ? fs::path(env) : fs::temp_directory_path() / "atmos_test") /
                         ("fuzz_sweep_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "adir");
    fs::create_directories(dir / "ck.bin");
    fs::create_directories(dir / "mine");
    std::ofstream(dir / "mine" / "notes.txt") << "mine\n";
    std::ofstream(dir / "q.csv") << "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.5,0\n";
    std::ofstream(dir / "long.csv") << "altitude_m,mu,mu_s,azimuth_deg\n"
                                    << std::string(5000, '1') << ",0,0,0\n";
    static const char kHugePng[] =
        "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00"
        "\x4e\x20\x00\x00\x4e\x20\x08\x02\x00\x00\x00\x6c\x12\xd1\x6e";
    std::ofstream(dir / "huge.png", std::ios::binary).write(kHugePng, sizeof kHugePng - 1);
    fs::create_symlink("/dev/zero", dir / "zero.bin");
    fs::create_symlink("none.csv", dir / "dangling.csv");
    ASSERT_EQ(::mkfifo((dir / "fifock.bin").c_str(), 0600), 0);
    const bool devices = IsCharDevice("/dev/null") && IsCharDevice("/dev/zero");

    std::ifstream data(ATMOS_TEST_DATA "/fuzz/bad_inputs.tsv");
    ASSERT_TRUE(data) << ATMOS_TEST_DATA "/fuzz/bad_inputs.tsv";
    int cases = 0, refused = 0, held = 0;
    for (std::string line; std::getline(data, line);) {
        if (line.empty() || line[0] == '#') continue;
        const size_t t1 = line.find('\t'), t2 = line.find('\t', t1 + 1);
        ASSERT_NE(t2, std::string::npos) << line;
        const int status = std::stoi(line.substr(0, t1));
        const std::string needle = line.substr(t1 + 1, t2 - t1 - 1);
        std::string args = line.substr(t2 + 1);
        for (size_t at; (at = args.find("{dir}")) != std::string::npos;) {
            args.replace(at, 5, dir.string());
        }
        if (!devices && args.find("/dev/") != std::string::npos) continue;  // broken host
        ++cases;
        const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
        const std::string cmd = std::string(ATMOS_CLI_PATH) + " " + args + " < /dev/null > " +
                                out.string() + " 2> " + err.string();
        const int raw = std::system(cmd.c_str());
        const int got = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
        const std::string text = Slurp(err);
        EXPECT_EQ(got, status) << args << "\n" << text;
        if (status == 0) {
            ++held;
            continue;
        }
        ++refused;
        EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << args << "\n" << text;
        EXPECT_EQ(text.rfind("atmos: error: ", 0), 0u) << args << "\n" << text;
        EXPECT_NE(text.find(needle), std::string::npos)
            << args << "\nwanted: " << needle << "\ngot: " << text;
        EXPECT_FALSE(fs::exists(dir / "x.exr")) << args;
        EXPECT_FALSE(fs::exists(dir / "w.json")) << args;
        EXPECT_FALSE(fs::exists(dir / "missing")) << args;
    }
    EXPECT_EQ(Slurp(dir / "mine" / "notes.txt"), "mine\n");
    if (devices) {
        EXPECT_TRUE(IsCharDevice("/dev/null"));
        EXPECT_TRUE(IsCharDevice("/dev/zero"));
    }
    std::printf("fuzz sweep: %d cases, %d refused with one line, %d held\n", cases, refused, held);
    EXPECT_GE(cases, 20);
    fs::remove_all(dir);
}

}  // namespace
