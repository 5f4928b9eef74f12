// Issue 18 items 6, 7, 8 and 11: every command's bad inputs get one clear line
// ("atmos: error: ...") and exit 2, before any work: malformed sizes, NaN,
// infinite and huge values, hexadecimal numbers, wrong types, missing files,
// unwritable paths, a model asked for a quantity it does not produce, bad
// `sample` rows (named by line), duplicate keys and oversized atmosphere files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using atmos_test::Slurp;
using Outcome = atmos_test::CommandOutcome;

fs::path SweepDir() { return atmos_test::TestTmpDir("bad_input_" + std::to_string(getpid())); }

Outcome Atmos(const fs::path& dir, const std::string& args, const std::string& input) {
    static int counter = 0;
    return atmos_test::RunAtmosWithInput(dir, std::to_string(++counter), args, input);
}

struct Case {
    Case(std::string a, std::string n, std::string i = "")
        : args(std::move(a)), needle(std::move(n)), input(std::move(i)) {}
    std::string args;
    std::string needle;  // in the one error line
    std::string input;   // stdin
};

const char kHeader[] = "altitude_m,mu,mu_s,azimuth_deg\n";

TEST(BadInput, EveryCommandGivesOneLineAndExitTwo) {
    const fs::path dir = SweepDir();
    const std::string d = dir.string();
    // Atmosphere files: a duplicate key, an oversized file, a syntax error, a
    // wrong type.
    const std::string earth = atmos::AtmosphereToJson(atmos::EarthAtmosphere());
    std::ofstream(dir / "dup.json") << "{\n  \"mie_phase_g\": 0.5," << earth.substr(1);
    {
        std::ofstream big(dir / "big.json");
        big << earth.substr(0, earth.size() - 2) << ",\n  \"description\": \"";
        big << std::string(2u << 20, 'x') << "\"\n}\n";
    }
    std::ofstream(dir / "syntax.json") << "{\"bottom_radius\": 6360000,,}";
    std::string typed = earth;
    typed.replace(typed.find("\"mie_phase_g\": 0.8"), 18, "\"mie_phase_g\": \"high\"");
    std::ofstream(dir / "type.json") << typed;
    fs::create_directories(dir / "adir.exr");
    // Issue 38 item 6: a PNG whose header claims 20000x20000 (33 bytes; it
    // cost 5.9 GB and 55 s), a query line of 5000 characters.
    {
        static const char kHugePng[] =
            "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00"
            "\x4e\x20\x00\x00\x4e\x20\x08\x02\x00\x00\x00\x6c\x12\xd1\x6e";
        std::ofstream(dir / "huge.png", std::ios::binary).write(kHugePng, sizeof kHugePng - 1);
    }
    std::error_code ignored;
    fs::create_symlink("/dev/zero", dir / "zero.bin", ignored);
    const std::string out = " -o " + d + "/x.exr";
    const std::vector<Case> cases = {
        // Sizes.
        {"render --size 0x10" + out, "malformed size"},
        {"render --size 10x" + out, "malformed size"},
        {"render --size 99999999999x2" + out, "malformed size"},
        {"render --size -4x4" + out, "malformed size"},
        {"compare --size 0x0 -o " + d + "/cmp", "malformed size"},
        {"bench --size axb", "malformed size"},
        // Output paths, checked before the work.
        {"render --size 8x4 -o " + d + "/x.txt", "unknown extension"},
        {"render --size 8x4 -o " + d + "/missing/x.exr", "does not exist"},
        {"render --size 8x4 -o /proc/atmos-test.exr", "cannot write '/proc/atmos-test.exr'"},
        {"render --size 8x4 -o " + d + "/adir.exr", "is a directory"},
        {"bake --model hillaire -o /proc/atmos-test", "/proc/atmos-test"},
        {"fit --model neural -o " + d + "/missing/w.json", "does not exist"},
        {"compare --models naive --views ground-noon --size 8x4 -o /proc/atmos-test",
         "/proc/atmos-test"},
        // Quantities a model does not produce.
        {"render --model transmittance-flat --quantity radiance --size 8x4" + out,
         "does not produce radiance"},
        {"render --model preetham --quantity transmittance --size 8x4" + out,
         "does not produce transmittance"},
        {"bench --models transmittance-flat --size 8x4", "does not produce radiance"},
        {"compare --models preetham --quantity transmittance -o " + d + "/cmp",
         "does not produce transmittance"},
        {"fit --model neural --reference preetham -o " + d + "/w.json", "cannot be a reference"},
        // Fit options, checked before the reference's precomputation (issue 15).
        {"fit --model neural --encoding nope -o " + d + "/w.json", "--encoding"},
        {"fit --model neural --encoding horizon -o " + d + "/w.json", "needs --network large"},
        {"fit --model neural --network large --loss-epsilon 0 -o " + d + "/w.json",
         "--loss-epsilon"},
        {"fit --model neural --horizon-fraction 2 -o " + d + "/w.json", "--horizon-fraction"},
        // A negative value once meant "the network's own" silently.
        {"fit --model neural --horizon-fraction -0.5 -o " + d + "/w.json", "--horizon-fraction"},
        {"fit --model neural --loss-epsilon -1 -o " + d + "/w.json", "--loss-epsilon"},
        {"fit --model neural --loss-epsilon nan -o " + d + "/w.json", "--loss-epsilon"},
        // Issue 39 item 3: training settings (inf trained NaN weights, exit 0).
        {"fit --model neural --learning-rate inf -o " + d + "/w.json", "--learning-rate"},
        {"fit --model neural --learning-rate nan -o " + d + "/w.json", "--learning-rate"},
        {"fit --model neural --learning-rate 5 -o " + d + "/w.json", "--learning-rate"},
        {"fit --model neural --final-learning-rate inf -o " + d + "/w.json",
         "--final-learning-rate"},
        {"fit --model neural --scattering-samples 2000000000 -o " + d + "/w.json",
         "--scattering-samples"},
        {"render --quantity colour --size 8x4" + out, "unknown quantity"},
        // Models and their options: NaN, infinity, hexadecimal, out of range, wrong type.
        {"render --model nope --size 8x4" + out, "unknown model 'nope'"},
        {"render --model naive:steps=nan --size 8x4" + out, "steps"},
        {"render --model naive:steps=inf --size 8x4" + out, "steps"},
        {"render --model naive:steps=0x10 --size 8x4" + out, "steps"},
        {"render --model naive:steps=1e400 --size 8x4" + out, "steps"},
        {"render --model naive:steps=2.5 --size 8x4" + out, "steps"},
        {"render --model naive:steps=0 --size 8x4" + out, "steps"},
        {"render --model naive:nope=1 --size 8x4" + out, "nope"},
        {"list nope", "unknown model 'nope'"},
        // Atmospheres: fields, files.
        {"render --set bottom_radius=nan --size 8x4" + out, "bottom_radius"},
        {"render --set bottom_radius=0x10 --size 8x4" + out, "0x10"},
        {"render --set solar_irradiance=1e308 --size 8x4" + out, "solar_irradiance"},
        {"render --set mie_phase_g=inf --size 8x4" + out, "mie_phase_g"},
        {"render --set mie_phase_g=1e400 --size 8x4" + out, "out of the range"},
        {"render --set ground_albedo=abc --size 8x4" + out, "abc"},
        {"render --set ground_albedo=2 --size 8x4" + out, "ground_albedo"},
        {"render --set nope=1 --size 8x4" + out, "nope"},
        {"render --atmosphere " + d + "/none.json --size 8x4" + out, "unknown atmosphere"},
        {"render --atmosphere " + d + "/dup.json --size 8x4" + out,
         "\"mie_phase_g\" appears twice"},
        {"render --atmosphere " + d + "/big.json --size 8x4" + out, "more than the 1 MiB"},
        {"render --atmosphere " + d + "/syntax.json --size 8x4" + out, "JSON syntax error"},
        {"render --atmosphere " + d + "/type.json --size 8x4" + out, "mie_phase_g"},
        {"render --atmosphere " + d + " --size 8x4" + out, d},
        // Views, flags.
        {"render --view nope --size 8x4" + out, "nope"},
        {"render --exposure nan --size 8x4" + out, "--exposure"},
        {"render --threads -1 --size 8x4" + out, "--threads"},
        {"render --threads abc --size 8x4" + out, "--threads"},
        {"render --model reference --spp 0 --size 8x4" + out, "--spp"},
        {"render --model naive --spp 4 --size 8x4" + out, "--spp"},
        {"render --backend gpu --size 8x4" + out, "gpu"},
        {"frobnicate", "unknown command 'frobnicate'"},
        // sample: the line and the field are named; one number parser.
        {"sample", "no input", ""},
        {"sample", "line 1: expected the header", "a,b,c\n"},
        {"sample", "line 2: altitude_m '0x10' is not a number",
         std::string(kHeader) + "0x10,0,0,0\n"},
        {"sample", "line 2: mu 'nan' is not a finite number", std::string(kHeader) + "0,nan,0,0\n"},
        {"sample", "line 2: mu_s 'inf' is not a finite number",
         std::string(kHeader) + "0,0,inf,0\n"},
        {"sample", "line 2: altitude_m '1e400' is out of the range of a double",
         std::string(kHeader) + "1e400,0,0,0\n"},
        {"sample", "line 3: mu must be in [-1, 1]", std::string(kHeader) + "0,0,0,0\n0,2,0,0\n"},
        {"sample", "line 2: altitude_m must be >= 0", std::string(kHeader) + "-1,0,0,0\n"},
        {"sample", "line 2: expected 4", std::string(kHeader) + "0,0,0\n"},
        {"sample", "line 2: azimuth_deg 'x' is not a number", std::string(kHeader) + "0,0,0,x\n"},
        // Images: missing files, bad flags.
        {"flip " + d + "/none1.exr " + d + "/none2.exr", d + "/none1.exr"},
        {"rmse " + d + "/none1.exr " + d + "/none2.exr", "cannot read EXR"},
        {"flip --ppd -1 " + d + "/none1.exr " + d + "/none2.exr", "--ppd"},
        {"compare --ppd -1 -o " + d + "/cmp", "--ppd"},
        {"fit --model naive -o " + d + "/w.json", "only --model neural"},
        {"bench --repeat 0 --size 8x4", "--repeat"},
        // Issue 38 item 6: bounded inputs, each one line before the memory grows.
        {"loc --file /dev/zero", "larger than the 64 MiB"},
        {"sample -i /dev/zero", "line 1 is longer than 4096 characters"},
        {"sample", "line 2 is longer than 4096 characters",
         std::string(kHeader) + std::string(5000, '1') + ",0,0,0\n"},
        {"flip " + d + "/huge.png " + d + "/huge.png", "claims 20000x20000"},
        {"render --model reference --size 8x4 --spp 2 --resume --checkpoint " + d + "/zero" + out,
         "not a regular file"},
    };
    const auto start = std::chrono::steady_clock::now();
    for (const Case& c : cases) {
        const Outcome r = Atmos(dir, c.args, c.input);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("atmos: error: ", 0), 0u) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.needle), std::string::npos)
            << c.args << "\nwanted: " << c.needle << "\ngot: " << r.err;
        EXPECT_FALSE(fs::exists(dir / "x.exr")) << c.args << ": wrote an output";
        // No 309-digit numbers in range messages (CLI11's NonNegativeNumber).
        size_t digits = 0, longest = 0;
        for (char ch : r.err) {
            digits = (ch >= '0' && ch <= '9') ? digits + 1 : 0;
            longest = std::max(longest, digits);
        }
        EXPECT_LE(longest, 20u) << c.args << "\n" << r.err;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%zu bad inputs in %.2f s\n", cases.size(), seconds);
    fs::remove_all(dir);
}

// Issue 18 item 8: numbers are read one way everywhere: a denormal is a number.
TEST(BadInput, SampleReadsDenormals) {
    const fs::path dir = SweepDir();
    const Outcome r = Atmos(dir, "sample --model flat", std::string(kHeader) + "1e-320,1,1,0\n");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 2) << r.out;  // header + 1 row
    fs::remove_all(dir);
}

}  // namespace
