// End-to-end tests of the `atmos` executable: outputs and every error path.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "base/parallel.h"
#include "io/image_formats.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using atmos_test::Slurp;
using Result = atmos_test::CommandOutcome;

fs::path TempDir() { return atmos_test::TestTmpDir("cli"); }

// Runs `atmos ARGS` (stdin from `input` if not empty), capturing both streams.
Result RunAtmos(const std::string& args, const std::string& input = "") {
    static int counter = 0;
    // Unique per process: ctest runs each test in its own process, in parallel.
    const std::string id = std::to_string(getpid()) + "_" + std::to_string(++counter);
    return atmos_test::RunAtmosWithInput(TempDir(), id, args, input);
}

bool HaveStrace() { return std::system("strace -o /dev/null true > /dev/null 2>&1") == 0; }

// An error: non-zero exit and exactly one line on stderr, mentioning `needle`.
void ExpectError(const std::string& args, const std::string& needle,
                 const std::string& input = "") {
    const Result r = RunAtmos(args, input);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_NE(r.status, -1) << args << " crashed";
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("atmos: error: ", 0), 0u) << r.err;
}

TEST(Cli, List) {
    const Result r = RunAtmos("list");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("naive"), std::string::npos);
    EXPECT_NE(r.out.find("planet-shadow-orbit"), std::string::npos);
    EXPECT_NE(r.out.find("earth-bruneton"), std::string::npos);
}

TEST(Cli, RenderWritesEveryFormat) {
    for (const char* ext : {"exr", "png", "npy", "pfm"}) {
        const fs::path out = TempDir() / (std::string("render.") + ext);
        fs::remove(out);
        const Result r = RunAtmos("render --model naive --view ground-sunrise --size 32x18 -q -o " +
                                  out.string());
        EXPECT_EQ(r.status, 0) << r.err;
        ASSERT_TRUE(fs::exists(out)) << ext;
        const atmos::Image image = atmos::ReadImage(out.string());
        EXPECT_EQ(image.width(), 32);
        EXPECT_EQ(image.height(), 18);
    }
}

TEST(Cli, RenderAllViewsWritesAGallery) {
    const fs::path dir = TempDir() / "gallery";
    fs::remove_all(dir);
    const Result r = RunAtmos("render --model naive --view all --size 16x9 -q -o " + dir.string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "index.html"));
    EXPECT_TRUE(fs::exists(dir / "naive-space.png"));
    EXPECT_TRUE(fs::exists(dir / "naive-orbit-noon.exr"));
    const std::string html = Slurp(dir / "index.html");
    EXPECT_NE(html.find("naive-planet-shadow-ground.png"), std::string::npos);
}

// `atmos bake`: beside the EXR files, the raw blobs the JSON describes and the
// shaders (bruneton; tiny tables, one order: this checks the files, not the sky).
TEST(Cli, BakeWritesRawTablesAndShaders) {
    const fs::path dir = TempDir() / "bake_raw";
    fs::remove_all(dir);
    const Result r = RunAtmos(
        "bake --model bruneton:orders=1:scattering-r=4:scattering-mu=8:scattering-mu-s=4:"
        "scattering-nu=2:transmittance-width=8:transmittance-height=4:irradiance-width=4:"
        "irradiance-height=2 -q -o " +
        dir.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(Slurp(dir / "bruneton.json"));
    for (const char* format : {"float32", "float16"}) {
        const auto& blob = j.at("raw").at(format);
        EXPECT_EQ(fs::file_size(dir / blob.at("file").get<std::string>()),
                  blob.at("bytes").get<size_t>());
    }
    const auto& s = j.at("raw").at("tables").at("scattering");
    EXPECT_EQ(s.at("width"), 8);  // NU * MU_S
    EXPECT_EQ(s.at("height"), 8);
    EXPECT_EQ(s.at("depth"), 4);
    EXPECT_EQ(s.at("channels"), 3);
    EXPECT_TRUE(j.at("raw").at("tables").contains("single_mie_scattering"));
    const std::string glsl = Slurp(dir / "shaders" / "bruneton.glsl");
    EXPECT_NE(glsl.find("vec3 atmos_SkyRadiance("), std::string::npos);
    const std::string constants = Slurp(dir / "shaders" / "bruneton_constants.glsl");
    EXPECT_NE(constants.find("#define ATMOS_SCATTERING_MU 8\n"), std::string::npos);
    EXPECT_NE(constants.find("#define ATMOS_COMBINED_MIE 0\n"), std::string::npos);
    // The shared helpers (GLSL has no #include): installed, and listed in the
    // order a program concatenates them.
    EXPECT_NE(Slurp(dir / "shaders" / "common.glsl").find("bool atmos_ClipToAtmosphere("),
              std::string::npos);
    EXPECT_EQ(j.at("shaders").at("order"),
              nlohmann::json({"shaders/bruneton_constants.glsl", "shaders/common.glsl",
                              "shaders/bruneton.glsl"}));
}

TEST(Cli, SampleFollowsTheContract) {
    const Result r = RunAtmos("sample --model naive",
                              "altitude_m,mu,mu_s,azimuth_deg\n0,1,1,0\n1000,-0.5,0.5,30\n");
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream lines(r.out);
    std::string header, first, second;
    std::getline(lines, header);
    std::getline(lines, first);
    std::getline(lines, second);
    EXPECT_EQ(header, "altitude_m,mu,mu_s,azimuth_deg,L_r,L_g,L_b,T_r,T_g,T_b");
    EXPECT_EQ(std::count(first.begin(), first.end(), ','), 9);
    EXPECT_NE(second.find(",0,0,0"), std::string::npos) << second;  // hits the ground: T = 0
}

// Issue 19: --input/--output NPY give the CSV path's answers. Issue 37: the
// CSV text is each number's shortest form that reads back to the same double
// (queries) or float (answers): "0.1" where "%.17g" printed
// 0.10000000000000001.
TEST(Cli, SampleNpyInputAndOutputMatchTheCsv) {
    const fs::path dir = TempDir();
    const std::vector<float> q = {0.0f, 1.0f,  1.0f,    0.0f,   1000.0f,  -0.5f,
                                  0.5f, 30.0f, 2500.0f, 0.125f, 0.03125f, 200.0f};
    const fs::path in = dir / "q.npy", out = dir / "a.npy";
    atmos::detail::WriteNpyArray(in.string(), {3, 4}, q.data());
    const Result npy =
        RunAtmos("sample --model naive --input " + in.string() + " --output " + out.string(), "");
    ASSERT_EQ(npy.status, 0) << npy.err;
    const atmos::detail::NpyArray a = atmos::detail::ReadNpyArray(out.string());
    ASSERT_EQ(a.shape, (std::vector<std::uint64_t>{3, 6}));
    const Result csv = RunAtmos("sample --model naive",
                                "altitude_m,mu,mu_s,azimuth_deg\n0,1,1,0\n1000,-0.5,0.5,30\n"
                                "2500,0.125,0.03125,200\n");
    ASSERT_EQ(csv.status, 0) << csv.err;
    const char* const echoes[3] = {"0,1,1,0,", "1000,-0.5,0.5,30,", "2500,0.125,0.03125,200,"};
    std::istringstream lines(csv.out);
    std::string line;
    std::getline(lines, line);
    for (int i = 0; i < 3; ++i) {
        ASSERT_TRUE(std::getline(lines, line));
        ASSERT_EQ(line.rfind(echoes[i], 0), 0u) << line;
        std::istringstream fields(line.substr(std::strlen(echoes[i])));
        std::string field;
        for (int c = 0; c < 6; ++c) {
            ASSERT_TRUE(std::getline(fields, field, ',')) << line;
            // The same float, in at most 9 significant digits (%.9g's length).
            EXPECT_EQ(std::strtof(field.c_str(), nullptr), a.values[6 * i + c]) << field;
            char longest[64];
            std::snprintf(longest, sizeof longest, "%.9g", a.values[6 * i + c]);
            EXPECT_LE(field.size(), std::strlen(longest)) << field << " vs " << longest;
        }
    }
    // Doubles that decimal text cannot hold exactly echo as they were typed.
    const Result tenth = RunAtmos("sample --model naive",
                                  "altitude_m,mu,mu_s,azimuth_deg\n1234.5678,0.1,0.3,17.3\n");
    ASSERT_EQ(tenth.status, 0) << tenth.err;
    EXPECT_NE(tenth.out.find("\n1234.5678,0.1,0.3,17.3,"), std::string::npos) << tenth.out;
    ExpectError("sample --model naive --input " + out.string(),
                "expected an array of shape (N, 4)");
}

TEST(Cli, ModelOptionsReachTheModel) {
    const std::string in = "altitude_m,mu,mu_s,azimuth_deg\n0,0.05,0.1,0\n";
    const Result a = RunAtmos("sample --model naive:steps=4", in);
    const Result b = RunAtmos("sample --model naive:steps=64", in);
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_NE(a.out, b.out);
}

TEST(Cli, ErrorPaths) {
    const std::string o = " -o " + (TempDir() / "x.png").string();
    ExpectError("render --model nope --view ground-noon" + o, "unknown model 'nope'");
    ExpectError("render --view nowhere" + o, "unknown view 'nowhere'");
    ExpectError("render --view ground-noon --size 12" + o, "malformed size '12'");
    ExpectError("render --view ground-noon --size 0x10" + o, "malformed size");
    ExpectError("render --view ground-noon --size -3x10" + o, "size");
    ExpectError("render --view ground-noon --size 100000x10" + o, "malformed size");
    ExpectError("render --view ground-noon -o out.jpg", "out.jpg");
    ExpectError("render --view ground-noon", "-o");
    ExpectError("render --view ground-noon --quantity colour" + o, "unknown quantity");
    ExpectError("render --atmosphere /no/such/file.json" + o, "/no/such/file.json");
    ExpectError("render --set mie_phase_g=1.5" + o, "mie_phase_g");
    ExpectError("render --set no_such_field=1" + o, "no_such_field");
    ExpectError("render --set mie_phase_g" + o, "mie_phase_g");
    ExpectError("render --model empty:steps=3" + o, "model empty has no option 'steps'");
    ExpectError("render --model naive:steps=0" + o,
                "model naive: option steps must be an integer in [1, 100000], got '0'");
    ExpectError("render --model naive:steps=many" + o, "got 'many'");
    ExpectError("render --model naive:steps=2.5" + o, "got '2.5'");
    ExpectError("render --model naive:steps" + o, "expected NAME:OPTION=VALUE");
    ExpectError("render --model naive:steps=4:steps=5" + o, "given twice");
    ExpectError("render --model atmosphere-plus:orders=0" + o,
                "model atmosphere-plus: option orders must be an integer in [1, 20]");
    ExpectError("render --model bruneton:scattering-mu=17" + o, "must be even");
    ExpectError("render --model atmosphere-plus:parameterization=linear:p-u=2" + o,
                "p-u does not apply");
    // The old syntax (a model option as a flag) says where options go now.
    ExpectError("render --model naive --steps 3" + o, "--model naive:steps=VALUE");
    ExpectError("render --bogus-flag" + o, "bogus");
    // FLIP's pixels per degree: 1e12 overflowed the filter radius (SIGSEGV), 1e9 hung.
    for (const char* ppd : {"1e12", "1e9", "-1", "nan"}) {
        ExpectError(std::string("flip a.exr b.exr --ppd ") + ppd, "--ppd must be in (0, 10000]");
        ExpectError(
            std::string("compare --models empty --views space --size 8x4 --no-cache --ppd ") + ppd +
                " -o " + (TempDir() / "ppd").string(),
            "--ppd must be in (0, 10000]");
    }
    ExpectError("frobnicate", "frobnicate");
    ExpectError("bake --model naive -o " + (TempDir() / "bake").string(), "no precomputed tables");
    ExpectError("bake --model naive", "--output");
    // Every model is checked before any is baked (bruneton's bake would take seconds).
    ExpectError("viewer --models bruneton,preetham -o " + (TempDir() / "viewer").string(),
                "has no shaders");
    ExpectError("viewer --models bruneton,bruneton --load /nonexistent -o " +
                    (TempDir() / "viewer").string(),
                "one model");
    ExpectError("viewer --models bruneton", "--output");
    ExpectError("viewer --model naive -o " + (TempDir() / "viewer").string(), "has no shaders");
    ExpectError("viewer --model bruneton --models bruneton -o " + (TempDir() / "viewer").string(),
                "not both");
    ExpectError("render --model naive --load /nonexistent" + o, "no precomputed tables to load");
    ExpectError("sample --model naive", "header", "");
    ExpectError("sample --model naive", "header", "a,b,c\n");
    ExpectError("sample --model naive", "not a finite number",
                "altitude_m,mu,mu_s,azimuth_deg\n0,nan,1,0\n");
    ExpectError("sample --model naive", "line 2", "altitude_m,mu,mu_s,azimuth_deg\n0,1,1\n");
    ExpectError("sample --model naive", "mu must be", "altitude_m,mu,mu_s,azimuth_deg\n0,2,1,0\n");
    ExpectError("sample --model naive", "altitude_m must",
                "altitude_m,mu,mu_s,azimuth_deg\n-5,1,1,0\n");
    const fs::path bad_json = TempDir() / "bad.json";
    std::ofstream(bad_json) << "{ \"bottom_radius\": 6360e3, ";
    ExpectError("render --atmosphere " + bad_json.string() + o, "bad.json");
}

// --backend: a bad name is an error; cuda is one clear error where it cannot
// run (no CUDA in the build, or no device), and renders where it can.
TEST(Cli, BackendOption) {
    const std::string o = " -o " + (TempDir() / "backend.exr").string();
    ExpectError("render --view ground-noon --size 8x4 --backend gpu" + o, "unknown backend 'gpu'");
    if (!atmos::HasCudaSupport()) {
        const std::string no_cuda =
            "this build has no CUDA support; configure with -DATMOS_CUDA=ON";
        ExpectError("render --view ground-noon --size 8x4 --backend cuda" + o, no_cuda);
        ExpectError("sample --backend cuda", no_cuda, "altitude_m,mu,mu_s,azimuth_deg\n0,1,1,0\n");
        ExpectError("bench --models empty --views ground-noon --size 8x4 --backend cuda -o " +
                        (TempDir() / "backend.csv").string(),
                    no_cuda);
        ExpectError(
            "compare --models empty --views ground-noon --size 8x4 --no-cache --backend "
            "cuda -o " +
                (TempDir() / "backend_compare").string(),
            no_cuda);
        return;
    }
    const Result r = RunAtmos("render --view ground-noon --size 8x4 -q --backend cuda" + o);
    if (r.status != 0) {
        EXPECT_NE(r.err.find("cudaGetDeviceCount returned"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
}

TEST(Cli, FitWritesWeightsTheModelLoads) {
    // A tiny fit against the cheap `naive` model; the neural model then loads it.
    const std::string w = (TempDir() / "neural_fit.json").string();
    const Result r = RunAtmos(
        "fit --model neural --reference naive --transmittance-samples 200 --scattering-samples 400 "
        "--transmittance-iterations 50 --scattering-iterations 50 -o " +
        w);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("held-out"), std::string::npos) << r.out;
    const std::string png = (TempDir() / "neural_fit.png").string();
    const Result render = RunAtmos("render --model neural:weights=" + w +
                                   " --view ground-noon --size 16x9 -q -o " + png);
    EXPECT_EQ(render.status, 0) << render.err;
    ExpectError("fit --model naive -o " + w, "only --model neural");
    ExpectError("fit --model neural --reference nope -o " + w, "nope");
    ExpectError(
        "render --model neural:weights=/no/such/w.json --view ground-noon --size 16x9 -o " + png,
        "/no/such/w.json");
    // Weights fitted to earth used with another atmosphere.
    ExpectError(
        "render --model neural --set top_radius=6420000 --view ground-noon --size 16x9 -o " + png,
        "another atmosphere");
}

// A command's --help lists its own flags only: no model's options.
TEST(Cli, Help) {
    for (const char* command : {"render", "sample", "bake", "compare", "bench"}) {
        const Result r = RunAtmos(std::string(command) + " --help");
        EXPECT_EQ(r.status, 0) << command;
        EXPECT_NE(r.out.find("--model"), std::string::npos) << command;
        for (const char* model_option : {"--steps", "--orders", "--max-order", "--turbidity"}) {
            EXPECT_EQ(r.out.find(model_option), std::string::npos)
                << command << " " << model_option;
        }
    }
}

// `atmos list NAME` prints the model's own option table: each option with the
// default and range of that model's table (not another model's option of the
// same name), and each printed default is the value the model uses when the
// option is not given.
TEST(Cli, ListModelPrintsItsOwnDefaults) {
    using namespace atmos;
    for (const ModelInfo& info : ListModels()) {
        const Result r = RunAtmos("list " + info.name);
        ASSERT_EQ(r.status, 0) << info.name << r.err;
        if (info.options.empty()) {
            EXPECT_NE(r.out.find("options: none"), std::string::npos);
        }
        const auto defaults = ResolveModelOptions(info.name, {});
        ASSERT_EQ(defaults.size(), info.options.size());
        for (size_t i = 0; i < info.options.size(); ++i) {
            const ModelOptionSpec& spec = info.options[i];
            EXPECT_EQ(defaults[i].first, spec.name);
            EXPECT_EQ(defaults[i].second, spec.default_value) << info.name << " " << spec.name;
            const std::string line = spec.name;
            const size_t at = r.out.find("\n  " + line + " ");
            ASSERT_NE(at, std::string::npos) << info.name << " " << spec.name << "\n" << r.out;
            const std::string rest = r.out.substr(at, r.out.find('\n', at + 1) - at);
            const std::string shown =
                spec.default_value.empty() ? "default (none)" : "default " + spec.default_value;
            EXPECT_NE(rest.find(shown), std::string::npos) << info.name << ": " << rest;
            EXPECT_NE(rest.find(spec.Describe()), std::string::npos) << info.name << ": " << rest;
            // The printed default, given explicitly, changes nothing (or is
            // refused where the model's rules forbid giving it, e.g. a power
            // of a mapping the model does not use).
            if (!spec.default_value.empty()) {
                try {
                    EXPECT_EQ(ResolveModelOptions(info.name, {{spec.name, spec.default_value}}),
                              defaults)
                        << info.name << " " << spec.name;
                } catch (const Error& e) {
                    EXPECT_NE(std::string(e.what()).find("does not apply"), std::string::npos)
                        << e.what();
                }
            }
        }
    }
    // Two models with an option of the same name show their own defaults.
    EXPECT_NE(RunAtmos("list atmosphere-plus").out.find("default 5"), std::string::npos);
    EXPECT_NE(RunAtmos("list bruneton").out.find("default 4"), std::string::npos);
    ExpectError("list nope", "unknown model 'nope'");
}

// --spp, --seed and --pass-spp: flags of render and sample, for Monte Carlo
// models only, each validated with one clear error.
TEST(Cli, MonteCarloFlags) {
    const std::string out = (TempDir() / "mc.exr").string();
    const std::string render = "render --view space --size 8x4 -q -o " + out + " ";
    for (const char* flags : {"--spp 4", "--seed 1", "--pass-spp 2"}) {
        ExpectError(render + "--model naive " + flags, "apply to Monte Carlo models only");
        ExpectError(std::string("sample --model naive ") + flags,
                    "apply to Monte Carlo models only", "altitude_m,mu,mu_s,azimuth_deg\n");
    }
    ExpectError(render + "--model reference --spp 0", "--spp must be at least 1");
    ExpectError(render + "--model reference --seed 4294967296",
                "--seed must be in [0, 4294967295]");
    ExpectError(render + "--model reference --seed -1", "--seed must be in [0, 4294967295]");
    ExpectError(render + "--model reference --pass-spp -1", "--pass-spp must be >= 0");
    ExpectError("compare --reference naive --reference-seed 3 -o " + out,
                "need a Monte Carlo reference model");
    ExpectError("compare --reference-spp 0 -o " + out, "--reference-spp must be at least 1");
    const Result ok = RunAtmos(render + "--model reference --spp 2 --seed 4294967295 --pass-spp 1");
    EXPECT_EQ(ok.status, 0) << ok.err;
    const Result s = RunAtmos("sample --model reference --spp 3 --seed 2",
                              "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.5,0\n");
    EXPECT_EQ(s.status, 0) << s.err;
    for (const char* command : {"render", "sample"}) {
        const Result help = RunAtmos(std::string(command) + " --help");
        for (const char* flag : {"--spp", "--seed", "--pass-spp"}) {
            EXPECT_NE(help.out.find(flag), std::string::npos) << command << " " << flag;
        }
    }
}

// Issue 18 item 1: a kill at any write, fsync or rename of a checkpoint
// (fault injection with strace) never makes --resume give a wrong image: a
// render of 4 spp is checkpointed, extending it to 8 is killed at the k-th such
// call, and the resumed render is the uninterrupted one.
TEST(Cli, CheckpointSurvivesAKillAtEveryWriteAndRename) {
    if (!HaveStrace()) GTEST_SKIP() << "strace is not available";
    const fs::path dir = atmos_test::FreshTestTmpDir("cli/kill");
    const std::string base =
        "render --model reference --view plane-dawn --size 24x12 -q --seed 3 "
        "--pass-spp 2 --checkpoint " +
        (dir / "ck").string() + " ";
    const Result full = RunAtmos(base + "--spp 8 -o " + (dir / "full.exr").string());
    ASSERT_EQ(full.status, 0) << full.err;
    const std::string want = Slurp(dir / "full.exr");
    // The checkpoint's write and fsync, the directory's fsync, its one rename,
    // and the output image's first write (the checkpoint then is complete).
    const std::pair<const char*, int> faults[] = {
        {"write", 1}, {"write", 2}, {"fsync", 1}, {"fsync", 2}, {"rename,renameat,renameat2", 1}};
    for (const auto& [call, when] : faults) {
        {
            fs::remove(dir / "ck.bin");
            ASSERT_EQ(RunAtmos(base + "--spp 4 --keep-checkpoint -o " + (dir / "half.exr").string())
                          .status,
                      0);
            const std::string inject = std::string("strace -f -o /dev/null -e trace=") + call +
                                       " -e inject=" + call +
                                       ":error=EIO:signal=SIGKILL:when=" + std::to_string(when) +
                                       " " + ATMOS_CLI_PATH + " ";
            const std::string killed = inject + base + "--spp 8 --resume -o " +
                                       (dir / "killed.exr").string() + " > /dev/null 2>&1";
            const int raw = std::system(killed.c_str());
            EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 128 + SIGKILL)
                << call << " " << when << ": the injected kill did not happen";
            fs::remove(dir / "resumed.exr");
            const Result resumed =
                RunAtmos(base + "--spp 8 --resume -o " + (dir / "resumed.exr").string());
            ASSERT_EQ(resumed.status, 0) << call << " " << when << ": " << resumed.err;
            EXPECT_TRUE(Slurp(dir / "resumed.exr") == want) << call << " " << when;
        }
    }
}

// Issue 18 item 10: the checkpoint is deleted once the image is written,
// unless --keep-checkpoint.
TEST(Cli, CheckpointDeletedAfterSuccessUnlessKept) {
    const fs::path dir = atmos_test::FreshTestTmpDir("cli/ckpt_delete");
    const std::string base = "render --model reference --view plane-dawn --size 8x4 -q --spp 2 ";
    ASSERT_EQ(RunAtmos(base + "-o " + (dir / "a.exr").string()).status, 0);
    EXPECT_TRUE(fs::exists(dir / "a.exr"));
    EXPECT_FALSE(fs::exists(dir / "a.ckpt.bin"));
    ASSERT_EQ(RunAtmos(base + "--keep-checkpoint -o " + (dir / "b.exr").string()).status, 0);
    EXPECT_TRUE(fs::exists(dir / "b.ckpt.bin"));
}

// Issue 18 item 10: SIGINT during a checkpointed render finishes the pass,
// writes the checkpoint and stops with one line saying how to resume.
TEST(Cli, SigintCheckpointsAndStops) {
    if (!fs::exists("/proc/self/status")) GTEST_SKIP() << "no /proc";
    const fs::path dir = atmos_test::FreshTestTmpDir("cli/sigint");
    // The render is spawned directly, with SIGINT and SIGTERM at their default
    // action and unblocked, whatever this test inherited: a CI that starts the
    // suite with SIGINT blocked (or ignored, as a shell's background job is)
    // would otherwise leave the signal pending or lose it, and the render
    // would run to its end (status 0; seen once in CI). The signal is sent
    // once the render catches SIGINT (bit 2 of SigCgt in /proc/PID/status):
    // a fixed delay raced the reference's Prepare() under the sanitizers, and
    // a SIGINT before the driver's handler ends the process (status 130).
    std::vector<std::string> argv_text = {
        ATMOS_CLI_PATH, "render",     "--model", "reference", "--view",
        "plane-dawn",   "--size",     "8x4",     "-q",        "--spp",
        "200000",       "--pass-spp", "1",       "-o",        (dir / "i.exr").string()};
    pid_t pid = 0;
    const int spawned = atmos_test::SpawnWithDefaultSignals(argv_text, (dir / "err").string(),
                                                            {SIGINT, SIGTERM}, &pid);
    ASSERT_EQ(spawned, 0) << std::strerror(spawned);
    // Wait until the render catches SIGINT or has ended.
    int raw = 0;
    const bool ended = atmos_test::WaitUntilCatching(pid, SIGINT, 5000, &raw);
    ASSERT_FALSE(ended) << "the render ended before it caught SIGINT: " << Slurp(dir / "err");
    ASSERT_EQ(kill(pid, SIGINT), 0);
    ASSERT_EQ(waitpid(pid, &raw, 0), pid);
    ASSERT_TRUE(WIFEXITED(raw)) << "ended by signal " << (WIFSIGNALED(raw) ? WTERMSIG(raw) : 0);
    EXPECT_EQ(WEXITSTATUS(raw), 2);
    const std::string err = Slurp(dir / "err");
    EXPECT_NE(err.find("atmos: error: interrupted by SIGINT after pass"), std::string::npos) << err;
    EXPECT_NE(err.find("--resume"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(fs::exists(dir / "i.ckpt.bin"));
    EXPECT_FALSE(fs::exists(dir / "i.exr"));
}

// Issue 18 item 10: a checkpoint may fall inside a pass. With
// --checkpoint-every 0 every band of one row is committed; a SIGINT delivered
// at the third commit (strace) stops the render inside its first pass with one
// line, and --resume finishes it to exactly the uninterrupted image.
TEST(Cli, SigintInsideAPassCheckpointsAndResumesToTheSameImage) {
    if (!HaveStrace()) GTEST_SKIP() << "strace is not available";
    const fs::path dir = atmos_test::FreshTestTmpDir("cli/sigint_band");
    const std::string base =
        "render --model reference --view plane-dawn --size 24x12 -q --seed 5 --spp 4 "
        "--pass-spp 2 --checkpoint-every 0 --checkpoint " +
        (dir / "ck").string() + " ";
    const Result full = RunAtmos(base + "-o " + (dir / "full.exr").string());
    ASSERT_EQ(full.status, 0) << full.err;
    const std::string renames = "rename,renameat,renameat2";
    // LeakSanitizer cannot run under ptrace: off for the traced run (the
    // process exits normally here, unlike the kill tests).
    const std::string cmd =
        "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" strace -f -o /dev/null -e "
        "trace=" +
        renames + " -e inject=" + renames + ":signal=SIGINT:when=3 " + ATMOS_CLI_PATH + " " + base +
        "-o " + (dir / "cut.exr").string() + " > /dev/null 2> " + (dir / "err").string();
    const int raw = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(raw));
    EXPECT_EQ(WEXITSTATUS(raw), 2);
    const std::string err = Slurp(dir / "err");
    EXPECT_NE(err.find("atmos: error: interrupted by SIGINT in pass 1 of 2"), std::string::npos)
        << err;
    EXPECT_NE(err.find("4 of 12 rows"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(dir / "cut.exr"));
    const Result resumed = RunAtmos(base + "--resume -o " + (dir / "resumed.exr").string());
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_TRUE(Slurp(dir / "resumed.exr") == Slurp(dir / "full.exr"));
    ExpectError("render --model reference --size 8x4 -q --checkpoint-every -1 -o " +
                    (dir / "x.exr").string(),
                "--checkpoint-every must be in [0, 1e6] seconds");
}

// Issue 18 item 9: long work shows progress. ATMOS_PROGRESS=1 draws every
// enabled bar (whatever stderr is, with its final line), so each command's
// bars can be checked here: `fit` (its samples and its training), Hillaire's
// `sample` (one bar over every sky-view group), the path tracer's `sample`,
// a Monte Carlo `render`. With --quiet there is none, and without the variable
// none either (stderr is a file here, not a terminal; checked on `fit`).
TEST(Cli, ProgressBarsShowUnlessQuiet) {
    const std::string w = (TempDir() / "progress_fit.json").string();
    const std::string img = (TempDir() / "progress.exr").string();
    const std::string two_groups =
        "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.5,0\n0,0.2,0.5,90\n1000,0.5,0.3,0\n";
    struct Case {
        std::string args, quiet, input;
        std::vector<std::pair<std::string, int>> bars;  // label, how many final lines
    };
    const std::vector<Case> cases = {
        {"fit --model neural --reference naive --transmittance-samples 50 "
         "--scattering-samples 50 --transmittance-iterations 20 --scattering-iterations 20 -o " +
             w,
         "--quiet",
         "",
         {{"sample [", 2}, {"fit: training [", 1}}},
        {"sample --model hillaire", "-q", two_groups, {{"sample [", 1}}},
        {"sample --model reference --spp 2", "-q", two_groups, {{"sample [", 1}}},
        {"render --model reference --view plane-dawn --size 8x4 --spp 2 -o " + img,
         "-q",
         "",
         {{"reference [", 1}}},
    };
    // Final lines: the bar full and the time taken (a redraw at 100 % says "ETA").
    auto count = [](const std::string& text, const std::string& needle) {
        int n = 0;
        for (size_t at = text.find(needle); at != std::string::npos;
             at = text.find(needle, at + 1)) {
            if (text.compare(at + needle.size(), 3, "ETA") != 0) ++n;
        }
        return n;
    };
    for (const Case& c : cases) {
        ::setenv("ATMOS_PROGRESS", "1", 1);
        const Result shown = RunAtmos(c.args, c.input);
        const Result quiet = RunAtmos(c.args + " " + c.quiet, c.input);
        ::unsetenv("ATMOS_PROGRESS");
        // Without the variable (the bars' one switch, shared): the first case only.
        const Result plain = &c == &cases.front() ? RunAtmos(c.args, c.input) : Result{0, "", ""};
        for (const Result* r : {&shown, &quiet, &plain}) ASSERT_EQ(r->status, 0) << c.args;
        for (const auto& [label, lines] : c.bars) {
            // A final line: the bar full, then the time and a newline.
            EXPECT_EQ(count(shown.err, label + "##############################] 100.0% "), lines)
                << c.args << "\n"
                << shown.err;
        }
        EXPECT_EQ(quiet.err.find("%"), std::string::npos) << c.args << "\n" << quiet.err;
        EXPECT_EQ(plain.err.find("%"), std::string::npos) << c.args << "\n" << plain.err;
    }
}

// Issue 18 item 10: compare -o DIR keeps its render cache under DIR.
TEST(Cli, CompareCachesUnderItsOutput) {
    const fs::path dir = TempDir() / "compare_cache";
    fs::remove_all(dir);
    const Result r = RunAtmos(
        "compare --models naive --reference flat --views ground-noon "
        "--size 8x4 --quiet --no-npy -o " +
        dir.string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "cache")) << r.err;
}

}  // namespace

// Issue 17: `sample --wavelengths` columns and units.
TEST(Cli, SampleWavelengthsAddsSpectralColumns) {
    const std::string in = "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.7,90\n";
    const Result r = RunAtmos("sample -m naive -a kider-2013 --wavelengths 360:371.75:2", in);
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream lines(r.out);
    std::string header, row;
    std::getline(lines, header);
    std::getline(lines, row);
    EXPECT_EQ(header, "altitude_m,mu,mu_s,azimuth_deg,L_360,L_371.75,X,Y,Z");
    std::vector<double> v;
    std::vector<std::string> texts;
    std::stringstream fields(row);
    std::string f;
    while (std::getline(fields, f, ',')) {
        v.push_back(std::stod(f));
        texts.push_back(f);
    }
    ASSERT_EQ(v.size(), 9u) << row;
    // Each answer (L, X, Y, Z) is its float's shortest round-trip text.
    for (size_t i = 4; i < texts.size(); ++i) {
        char shortest[64];
        const std::to_chars_result c = std::to_chars(
            shortest, shortest + sizeof shortest, std::stof(texts[i]), std::chars_format::general);
        EXPECT_EQ(texts[i], std::string(shortest, c.ptr)) << i;
    }
    // Spectral radiance of a clear sky at 360 nm: of the order of 0.05 W m^-2 sr^-1 nm^-1.
    EXPECT_GT(v[4], 0.01);
    EXPECT_LT(v[4], 0.5);
    // Y = 683 sum L y(nm) 11.75 nm over the two bins.
    const double y = 683.0 * 11.75 * (v[4] * 0.000003917 + v[5] * 0.0000157605);
    EXPECT_NEAR(v[7] / y, 1.0, 2e-2) << row;
    const Result list = RunAtmos("sample -m naive -a earth --wavelengths 440,550,680", in);
    ASSERT_EQ(list.status, 0) << list.err;
    EXPECT_EQ(list.out.rfind("altitude_m,mu,mu_s,azimuth_deg,L_440,L_550,L_680,X,Y,Z\n", 0), 0u);
    // --output x.npy: (queries, wavelengths + 3) float32, the CSV's L and X, Y, Z.
    const fs::path npy = TempDir() / "spectral_sample.npy";
    const Result n = RunAtmos(
        "sample -m naive -a kider-2013 --wavelengths 360:371.75:2 --output " + npy.string(), in);
    ASSERT_EQ(n.status, 0) << n.err;
    const atmos::detail::NpyArray array = atmos::detail::ReadNpyArray(npy.string());
    ASSERT_EQ(array.shape, (std::vector<std::uint64_t>{1, 5}));
    for (size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(array.values[i], std::stof(texts[i + 4])) << i;  // the same floats
    }
    ExpectError("sample -m naive --wavelengths 700:400:3", "--wavelengths", in);
    ExpectError("sample -m neural --wavelengths 400:700:4", "per-wavelength", in);
    ExpectError("render -m naive --wavelengths 400:700:x -o " + (TempDir() / "s.exr").string(),
                "--wavelengths");
}

// Issue 17: a spectral render writes the colour and the spectral EXR.
TEST(Cli, RenderWavelengthsWritesTheSpectralExr) {
    const fs::path out = TempDir() / "spectral.exr";
    const Result r = RunAtmos(
        "render -m flat -a earth-spectral --wavelengths 400:700:4 -s 8x5 -q -o " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::exists(out));
    const fs::path spectral = TempDir() / "spectral.spectral.exr";
    ASSERT_TRUE(fs::exists(spectral));
    const std::string bytes = Slurp(spectral);
    for (const char* name : {"S0.400nm", "S0.500nm", "S0.700nm", "spectralLayoutVersion"}) {
        EXPECT_NE(bytes.find(name), std::string::npos) << name;
    }
}

// Issue 17 item 2: preetham renders and samples with --wavelengths through its
// own spectral form (the CIE daylight spectrum); the sampled Y in cd m^-2 is the
// RGB sample's luminance x 683 x 106.86 nm (unit sun) up to the 10 nm quadrature.
TEST(Cli, PreethamWavelengths) {
    const std::string in =
        "altitude_m,mu,mu_s,azimuth_deg\n0,0.5,0.7,90\n0,0,0,0\n0,0.05,-0.1,10\n"
        "1000,0.9,0.2,180\n";
    const Result rgb = RunAtmos("sample -m preetham", in);
    const Result spectral = RunAtmos("sample -m preetham --wavelengths 380:780:41", in);
    ASSERT_EQ(rgb.status, 0) << rgb.err;
    ASSERT_EQ(spectral.status, 0) << spectral.err;
    std::istringstream a(rgb.out), b(spectral.out);
    std::string la, lb;
    std::getline(a, la);
    std::getline(b, lb);
    int rows = 0;
    while (std::getline(a, la) && std::getline(b, lb)) {
        std::vector<double> va, vb;
        std::stringstream fa(la), fb(lb);
        for (std::string f; std::getline(fa, f, ',');) va.push_back(std::stod(f));
        for (std::string f; std::getline(fb, f, ',');) vb.push_back(std::stod(f));
        ASSERT_EQ(vb.size(), 4u + 41u + 3u) << lb;
        for (size_t i = 4; i < vb.size(); ++i) EXPECT_TRUE(std::isfinite(vb[i]) && vb[i] >= 0.0);
        const double y_rgb = 0.2126729 * va[4] + 0.7151522 * va[5] + 0.0721750 * va[6];
        const double y = vb[4 + 41 + 1] / (683.0 * 106.856895);
        EXPECT_NEAR(y / y_rgb, 1.0, 1e-3) << la << "\n" << lb;  // measured 3.4e-4
        ++rows;
    }
    EXPECT_EQ(rows, 4);
    const fs::path out = TempDir() / "preetham_spectral.exr";
    const Result r = RunAtmos(
        "render -m preetham -a earth-spectral --sun-disc --wavelengths "
        "380:780:41 -s 16x9 -q -o " +
        out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::exists(TempDir() / "preetham_spectral.spectral.exr"));
    ExpectError("sample -m preetham --wavelengths 250:400:3", "outside the CIE daylight", in);
    ExpectError("render -m preetham --wavelengths 400:900:3 -o " + out.string(),
                "outside the CIE daylight");
}

// Issue 17: `validate kider-2013` on two captures (tests/data/kider-2013, a
// subset of the measurements). naive's errors against the measured sky; the
// figures are the regression (relative RMSE over the mean measured radiance).
TEST(Cli, ValidateKiderOnTwoCaptures) {
    const fs::path data = fs::path(ATMOS_SOURCE_DIR) / "tests" / "data" / "kider-2013";
    const Result r = RunAtmos("validate kider-2013 -q --models naive --data " + data.string());
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream lines(r.out);
    std::string line, overall;
    std::getline(lines, line);
    EXPECT_EQ(line.rfind("model,capture,scope,region,rel_rmse_percent,abs_rmse_1e-3", 0), 0u);
    int rows = 0;
    while (std::getline(lines, line)) {
        ++rows;
        if (line.rfind("naive,all,all,all,", 0) == 0) overall = line;
        EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    }
    EXPECT_GT(rows, 20);
    ASSERT_FALSE(overall.empty());
    std::vector<std::string> f;
    std::stringstream fields(overall);
    std::string item;
    while (std::getline(fields, item, ',')) f.push_back(item);
    ASSERT_EQ(f.size(), 9u);
    EXPECT_EQ(f[8], "6400");  // 2 captures x 80 directions x 40 bins
    // Measured: 49.20 % (naive, single scattering, is darker than the sky: 33.15e-3
    // modelled against 52.71e-3 measured on average; 48.33 % with clear-sky-models' sun).
    EXPECT_NEAR(std::stod(f[4]), 49.20, 0.5) << overall;
    EXPECT_LT(std::stod(f[6]), std::stod(f[7])) << overall;
    // One row per bin (all captures pooled) and clear-sky-models' range, 360-720 nm
    // (31 bins).
    EXPECT_NE(r.out.find("\nnaive,all,442.25nm,all,"), std::string::npos) << r.out;
    // 12:45's sample 74 is 7.1 deg from the sun: the near-sun region (gamma < 10 deg);
    // its sample 75 (9.4 deg) too, so the capture's near-sun row pools 2 x 40 values.
    const size_t near_sun = r.out.find("\nnaive,12:45,all,near-sun,");
    ASSERT_NE(near_sun, std::string::npos) << r.out;
    EXPECT_EQ(r.out.substr(r.out.find('\n', near_sun + 1) - 3, 3), ",80") << r.out;
    EXPECT_NE(r.out.find("\nnaive,all,818.25nm,all,"), std::string::npos) << r.out;
    const size_t csm = r.out.find("\nnaive,all,360-720nm,all,");
    ASSERT_NE(csm, std::string::npos) << r.out;
    EXPECT_NE(r.out.find(",4960\n", csm), std::string::npos);  // 160 directions x 31 bins
    // --values: the model radiance per direction and bin.
    const fs::path values = TempDir() / "validate_values.csv";
    const Result v = RunAtmos("validate kider-2013 -q --models naive --captures 12:45 --data " +
                              data.string() + " -o /dev/null --values " + values.string());
    ASSERT_EQ(v.status, 0) << v.err;
    std::istringstream value_lines(Slurp(values));
    std::getline(value_lines, line);
    EXPECT_EQ(line.rfind("model,capture,sample,L_360,L_371.75,", 0), 0u) << line;
    int value_rows = 0;
    while (std::getline(value_lines, line)) {
        ++value_rows;
        EXPECT_EQ(line.rfind("naive,12:45,", 0), 0u) << line;
        EXPECT_EQ(std::count(line.begin(), line.end(), ','), 42) << line;
    }
    EXPECT_EQ(value_rows, 80);
    ExpectError("validate kider-2013 --data /nonexistent", "kider_ref.csv");
    ExpectError("validate other", "unknown data set");
}

// Issue 18: text outputs (validate's CSV, compare's CSVs and HTML report,
// bench's CSVs) are written through a temporary file and one rename, like the
// images: a write that fails (here a file-size limit of 1 KiB, as a full disk
// would) is one clear error and leaves the previous file as it was and no
// temporary behind (std::ofstream left a truncated file under the final name).
TEST(Cli, TextOutputsAreWrittenAtomically) {
    if (std::system("bash -c 'ulimit -f 1' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no bash";
    const fs::path dir = atmos_test::FreshTestTmpDir("cli/atomic_text");
    const fs::path data = fs::path(ATMOS_SOURCE_DIR) / "tests" / "data" / "kider-2013";
    // 40 queries for sample's CSV outputs (each over 1 KiB).
    {
        std::ofstream q(dir / "q.csv");
        q << "altitude_m,mu,mu_s,azimuth_deg\n";
        for (int i = 0; i < 40; ++i) q << 100 * i << "," << 0.02 * i - 0.3 << ",0.5,30\n";
    }
    const std::string queries = " --input " + (dir / "q.csv").string() + " --output ";
    // Each command, its output checked, and the file-size limit (KiB) it runs under.
    const std::tuple<std::string, fs::path, int> cases[] = {
        {"validate kider-2013 -q --models naive --data " + data.string() + " -o " +
             (dir / "v.csv").string(),
         dir / "v.csv", 1},
        {"compare --models naive --reference flat --views ground-noon --size 8x4 --quiet "
         "--no-npy -o " +
             (dir / "cmp").string(),
         dir / "cmp" / "index.html", 1},
        {"sample --model naive" + queries + (dir / "s.csv").string(), dir / "s.csv", 1},
        {"sample --model naive --wavelengths 400:700:4" + queries + (dir / "w.csv").string(),
         dir / "w.csv", 1},
        // hillaire's bake: its EXR tables (at most 180 KB) fit under the limit,
        // tables.f32 (208,896 B) does not.
        {"bake -q --model hillaire -o " + (dir / "bake").string(), dir / "bake" / "tables.f32",
         190},
    };
    for (const auto& [args, target, limit_kib] : cases) {
        const Result first = RunAtmos(args);
        ASSERT_EQ(first.status, 0) << args << "\n" << first.err;
        const std::string before = Slurp(target);
        ASSERT_GT(before.size(), 1024u) << target;
        const std::string cmd = "bash -c \"trap '' XFSZ; ulimit -f " + std::to_string(limit_kib) +
                                "; exec " + std::string(ATMOS_CLI_PATH) + " " + args +
                                "\" > /dev/null 2> " + (dir / "err").string();
        const int raw = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(raw)) << args;
        EXPECT_EQ(WEXITSTATUS(raw), 2) << args;
        const std::string err = Slurp(dir / "err");
        EXPECT_EQ(err.rfind("atmos: error: cannot write '", 0), 0u) << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
        EXPECT_TRUE(Slurp(target) == before) << target << " changed";
        for (const auto& entry : fs::directory_iterator(target.parent_path())) {
            EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos)
                << entry.path();
        }
    }
}

// The fit's line "relative RMSE A % (start B %)" of a `validate --fit` run on
// the two test captures (tests/data/kider-2013): {A, B}, or a fatal failure.
namespace {
void RunValidateFit(const std::string& flags, Result* r, double* after, double* before) {
    const fs::path data = fs::path(ATMOS_SOURCE_DIR) / "tests" / "data" / "kider-2013";
    *r = RunAtmos("validate kider-2013 -q " + flags + " --data " + data.string());
    ASSERT_EQ(r->status, 0) << r->err;
    const size_t at = r->err.find("relative RMSE ");
    ASSERT_NE(at, std::string::npos) << r->err;
    ASSERT_EQ(
        std::sscanf(r->err.c_str() + at, "relative RMSE %lf %% (start %lf %%)", after, before), 2)
        << r->err;
}
}  // namespace

// Issue 17 item 4: --fit fits the aerosol (here with naive, cheap, on the two test
// captures and three bins), reports it and evaluates the models with it.
TEST(Cli, ValidateFitsTheAerosol) {
#ifndef ATMOS_HAVE_NLOPT
    GTEST_SKIP() << "built without NLopt";
#endif
    const fs::path data = fs::path(ATMOS_SOURCE_DIR) / "tests" / "data" / "kider-2013";
    Result r;
    double after = 0.0, before = 0.0;
    RunValidateFit("--models naive --fit --fit-model naive --fit-evaluations 12", &r, &after,
                   &before);
    if (HasFatalFailure()) return;
    EXPECT_LT(after, before - 1.0) << r.err;  // naive is far too dark: beta rises
    EXPECT_NE(r.err.find("--set mie_extinction.angstrom.beta="), std::string::npos) << r.err;
    // The models are evaluated with the fitted atmosphere: naive's overall error
    // is below its 49.20 % with the preset (ValidateKiderOnTwoCaptures).
    const size_t row = r.out.find("naive,all,all,all,");
    ASSERT_NE(row, std::string::npos) << r.out;
    EXPECT_LT(std::stod(r.out.substr(row + 18)), 45.0) << r.out.substr(row, 80);
    ExpectError("validate kider-2013 --fit --fit-model naive -a earth --data " + data.string(),
                "angstrom");
    ExpectError(
        "validate kider-2013 --fit --fit-model naive --fit-wavelengths 450 --data " + data.string(),
        "not a Kider bin");
}

// --fit-second-lobe also fits the second Cornette-Shanks lobe (six parameters),
// from kider-2013-aeronet's own lobe.
TEST(Cli, ValidateFitsTheSecondMieLobe) {
#ifndef ATMOS_HAVE_NLOPT
    GTEST_SKIP() << "built without NLopt";
#endif
    Result r;
    double after = 0.0, before = 0.0;
    RunValidateFit(
        "-a kider-2013-aeronet --models naive --fit --fit-model naive --fit-second-lobe "
        "--fit-evaluations 14",
        &r, &after, &before);
    if (HasFatalFailure()) return;
    EXPECT_NE(r.err.find("  g2      "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(start 0.94, bounds [0.5, 0.98])"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(start 0.1, bounds [0, 0.5])"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--set mie_phase_g2="), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--set mie_phase_weight2="), std::string::npos) << r.err;
    EXPECT_LE(after, before) << r.err;
}

// Issue 17: compare --wavelengths compares the spectral renders as linear sRGB.
TEST(Cli, CompareWavelengths) {
    const fs::path out = TempDir() / "compare_spectral";
    const Result r = RunAtmos(
        "compare -q --no-cache --models flat --reference naive --views ground-noon -s 8x5 "
        "-a kider-2013 --wavelengths 400:700:4 -o " +
        out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string flip = Slurp(out / "flip.csv");
    EXPECT_NE(flip.find("ground-noon,"), std::string::npos) << flip;
    ExpectError(
        "compare -q --no-cache --models neural --reference naive --wavelengths 400:700:4 "
        "-o " +
            out.string(),
        "per-wavelength");
}

// Issue 17 item 5: --reference-wavelengths compares RGB models with a spectral
// reference and with the RGB one (rgb_cost.csv).
TEST(Cli, CompareSpectralReference) {
    const fs::path out = TempDir() / "compare_rgb_cost";
    const Result r = RunAtmos(
        "compare -q --no-cache --models flat,naive --reference naive --views "
        "ground-noon,ground-sunrise "
        "-s 8x5 -a kider-2013 --white e --reference-wavelengths 400:700:4 -o " +
        out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream f(out / "rgb_cost.csv");
    std::string line;
    std::getline(f, line);
    EXPECT_EQ(line, "view,model,flip_spectral_reference,flip_rgb_reference,difference");
    int rows = 0;
    while (std::getline(f, line)) {
        ++rows;
        std::vector<double> v;
        std::stringstream ss(line.substr(line.find(',', line.find(',') + 1) + 1));
        std::string item;
        while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
        ASSERT_EQ(v.size(), 3u) << line;
        EXPECT_GE(v[1], 0.0) << line;
        if (line.find(",naive,") != std::string::npos) {
            // naive against the RGB naive reference: the same image; against the
            // spectral one it differs.
            EXPECT_EQ(v[1], 0.0) << line;
            EXPECT_GT(v[0], 0.0) << line;
        }
    }
    EXPECT_EQ(rows, 4);
    EXPECT_TRUE(fs::exists(out / "images" / "ground-noon" / "reference-rgb.png"));
    // The report says the reference is spectral.
    EXPECT_NE(Slurp(out / "index.html").find("rendered spectrally at 4 wavelengths"),
              std::string::npos);
    ExpectError(
        "compare -q --no-cache --models flat --reference naive --wavelengths 400:700:4 "
        "--reference-wavelengths 400:700:4 -o " +
            out.string(),
        "drop --wavelengths");
}
