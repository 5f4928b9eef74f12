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
#include <nlohmann/json.hpp>
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

// ATMOS_TEST_CLI=PATH runs the sweep against another atmos executable (to
// watch it fail on a build without the fixes).
std::string Cli() {
    const char* env = std::getenv("ATMOS_TEST_CLI");
    return env ? env : ATMOS_CLI_PATH;
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
    for (const char* fifo : {"fifo.pfm", "fifo.exr", "fifo.png"}) {
        ASSERT_EQ(::mkfifo((dir / fifo).c_str(), 0600), 0);
    }
    fs::create_directories(dir / "adir.exr");
    // Query CSVs, each with one fault.
    const std::string header = "altitude_m,mu,mu_s,azimuth_deg\n";
    const std::pair<const char*, std::string> texts[] = {
        {"empty.csv", ""},
        {"headonly.csv", header},
        {"qnan.csv", header + "nan,0.5,0.5,0\n"},
        {"qinf.csv", header + "0,inf,0.5,0\n"},
        {"qmu.csv", header + "0,1.5,0.5,0\n"},
        {"qneg.csv", header + "-5000,0.5,0.5,0\n"},
        {"qcols.csv", "altitude_m,mu,mu_s\n0,0.5,0.5\n"},
        {"qshort.csv", header + "0,0.5\n"},
        {"qjunk.csv", header + "0,0.5x,0.5,0\n"},
        {"qhex.csv", header + "0x10,0.5,0.5,0\n"},
        {"qbig.csv", header + "1e999,0.5,0.5,0\n"},
        {"qempty.csv", header + ",0.5,0.5,0\n"},
        {"qhdr.csv", "alt,mu,mu_s,azimuth_deg\n0,0.5,0.5,0\n"},
        {"qbin.csv", std::string("\x00\x01\x02\xff\xfe\n", 6)},
        {"x.txt", "hello\n"},
        // Files that claim a format and are not it.
        {"garbage.exr", "not an exr at all"},
        {"garbage.png", "\x89PNG\r\n\x1a\nxx"},
        {"garbage.npy", "\x93NUMPY\x01\x00garbage"},
        {"garbage.pfm", "PF\n-1 -1\n-1.0\n"},
        {"garbage.shard", "garbage"},
        // Atmospheres that are not JSON objects.
        {"a_bad.json", "{"},
        {"a_empty.json", ""},
        {"a_array.json", "[1,2,3]"},
    };
    for (const auto& [name, text] : texts) {
        std::ofstream(dir / name, std::ios::binary) << text;
    }
    // Atmospheres: earth with one field out of its range, of the wrong type,
    // unknown or missing.
    nlohmann::json earth;
    std::ifstream(ATMOS_SOURCE_DIR "/data/atmospheres/earth.json") >> earth;
    ASSERT_TRUE(earth.is_object());
    const std::pair<const char*, std::pair<const char*, nlohmann::json>> fields[] = {
        {"a_neg.json", {"bottom_radius", -1}},
        {"a_inv.json", {"top_radius", 6000000}},
        {"a_str.json", {"mie_phase_g", "0.8"}},
        {"a_g.json", {"mie_phase_g", 1.5}},
        {"a_albedo.json", {"ground_albedo", 2}},
        {"a_ray.json", {"rayleigh_scattering", {1, 2}}},
        {"a_rayneg.json", {"rayleigh_scattering", {-1e-6, 1e-6, 1e-6}}},
        {"a_unknown.json", {"bogus_field", 1}},
        {"a_null.json", {"mie_extinction", nullptr}},
        {"a_mie.json", {"mie_scattering", 1e-5}},
        {"a_sun.json", {"sun_angular_radius", 3}},
        {"a_mus.json", {"mu_s_min", 2}},
        {"a_dens.json", {"rayleigh_density", {{"scale_height", -5}}}},
        {"a_dens2.json", {"rayleigh_density", {{"bogus", 1}}}},
        {"a_big.json", {"bottom_radius", 1e300}},
    };
    for (const auto& [name, field] : fields) {
        nlohmann::json a = earth;
        a[field.first] = field.second;
        std::ofstream(dir / name) << a.dump();
    }
    nlohmann::json missing = earth;
    missing.erase("top_radius");
    std::ofstream(dir / "a_missing.json") << missing.dump();
    // A FIFO input that no one writes is refused after this wait (io/bounded_read.h).
    ::setenv("ATMOS_INPUT_WAIT_SECONDS", "0.2", 1);
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
        for (size_t at; (at = args.find("{data}")) != std::string::npos;) {
            args.replace(at, 6, ATMOS_TEST_DATA);
        }
        if (!devices && args.find("/dev/") != std::string::npos) continue;  // broken host
        ++cases;
        const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
        // A hang is a failure (status 124), not a stuck suite.
        const std::string cmd = "timeout -k 5 60 " + Cli() + " " + args + " < /dev/null > " +
                                out.string() + " 2> " + err.string();
        const int raw = std::system(cmd.c_str());
        const int got = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
        const std::string text = Slurp(err);
        EXPECT_EQ(got, status) << args << "\n" << text;
        // What the cases may write: nothing when refused (and removed after
        // a case that holds).
        const char* const outputs[] = {"x.exr", "x.shard", "w.json",
                                       "o.csv", "missing", "ckpt.bin"};
        if (status == 0) {
            ++held;
        } else {
            ++refused;
            EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << args << "\n" << text;
            EXPECT_EQ(text.rfind("atmos: error: ", 0), 0u) << args << "\n" << text;
            EXPECT_NE(text.find(needle), std::string::npos)
                << args << "\nwanted: " << needle << "\ngot: " << text;
            for (const char* o : outputs) EXPECT_FALSE(fs::exists(dir / o)) << args << ": " << o;
        }
        for (const char* o : outputs) fs::remove_all(dir / o);
    }
    EXPECT_EQ(Slurp(dir / "mine" / "notes.txt"), "mine\n");
    if (devices) {
        EXPECT_TRUE(IsCharDevice("/dev/null"));
        EXPECT_TRUE(IsCharDevice("/dev/zero"));
    }
    std::printf("fuzz sweep: %d cases, %d refused with one line, %d held\n", cases, refused, held);
    EXPECT_GE(cases, 300);
    fs::remove_all(dir);
}

}  // namespace
