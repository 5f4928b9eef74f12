// Issue 30 item 2: layers above the models decide by a model's declared
// capabilities, never by its name. A model defined in this file alone and
// registered at run time shows up in `list`, `compare` and `bench` (through the
// library functions those commands call); and no file above the models compares
// a model's name with a string literal.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "harness/compare.h"
#include "harness/listing.h"
#include "harness/loc.h"
#include "harness/spectral_run.h"
#include "models/evaluator_model.h"
#include "models/model_factory.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace atmos {
namespace {

// The test-only model: a grey sky of radiance `level`, transmittance 1 - level.
struct GreyOptions {
    double level = 0.25;
};

struct GreyEvaluator {
    // Test-only: not in models/model_list.h, so no CUDA kernel is instantiated for it.
    static constexpr bool kHostOnly = true;
    float level = 0.25f;
    ATMOS_HD RayResult Evaluate(const Vec3d&, const Vec3d&, const Vec3d&, bool) const {
        RayResult r;
        r.sky = Rgb(level);
        r.transmittance = Rgb(1.0f - level);
        return r;
    }
};

class GreyModel : public SimpleEvaluatorModel<GreyModel, GreyEvaluator> {
  public:
    static const OptionTable<GreyOptions>& OptionRows() {
        static const auto table = OptionTable<GreyOptions>().Real("level", &GreyOptions::level, 0.0,
                                                                  1.0, "", "the sky's radiance");
        return table;
    }
    explicit GreyModel(const GreyOptions& o) { evaluator_.level = static_cast<float>(o.level); }
    static ModelInfo StaticInfo() {
        ModelInfo info;
        info.name = "caps-test-grey";
        info.title = "Grey sky (test only)";
        info.citation = "tests/capabilities_test.cpp";
        info.summary = "a constant sky, registered by a test";
        info.capabilities.spectral = false;
        info.capabilities.validity_notes = {"grey everywhere"};
        info.domain.max_radius_ratio = 1.5;
        info.domain.radius_ratio_reason = "a test limit";
        info.thesis_name = "Grey";
        info.thesis_lines = 7;
        info.options = OptionRows().Specs();
        return info;
    }
    // The common path warns outside the declared domain (SetAtmosphere).
    void Prepare(const AtmosphereParameters& atmosphere) override { SetAtmosphere(atmosphere); }
};

// Registers the grey model for one test.
class GreyRegistered : public ::testing::Test {
  protected:
    void SetUp() override { RegisterModel(ModelFactoryOf<GreyModel>()); }
    void TearDown() override { UnregisterModel("caps-test-grey"); }
};

fs::path TempDir(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / ("atmos_caps_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

TEST_F(GreyRegistered, ListShowsItsDeclaredCapabilities) {
    bool listed = false;
    for (const ModelInfo& info : ListModels()) listed |= info.name == "caps-test-grey";
    EXPECT_TRUE(listed);
    const ModelInfo& info = GetModelInfo("caps-test-grey");
    const std::string text = ModelCapabilitiesText(info);  // what `atmos list` prints
    EXPECT_NE(text.find("validity: grey everywhere"), std::string::npos) << text;
    EXPECT_NE(text.find("radius ratio up to 1.5: a test limit"), std::string::npos) << text;
    EXPECT_FALSE(HasSpectralForm(info));  // compare/bench skip it in spectral runs
    EXPECT_EQ(ThesisLoc("caps-test-grey"), 7);
    EXPECT_EQ(ResolveModelOptions("caps-test-grey", {{"level", "0.5"}}).at(0).second, "0.5");
    EXPECT_THROW(RegisterModel(ModelFactoryOf<GreyModel>()), Error);  // once
}

TEST_F(GreyRegistered, CompareRunsIt) {
    CompareConfig config;
    config.models = {"caps-test-grey", "caps-test-grey:level=0.5"};
    config.views = {"ground-noon"};
    config.width = 8;
    config.height = 4;
    config.reference_model = "caps-test-grey";
    config.reference_options = {{"level", "0.5"}};
    config.atmosphere = EarthAtmosphere();
    config.output_dir = TempDir("compare").string();
    config.show_progress = false;
    const CompareResult result = RunCompare(config);
    ASSERT_EQ(result.model_names.size(), 2u);
    EXPECT_EQ(result.model_names[0], "caps-test-grey");
    ASSERT_EQ(result.rows.size(), 1u);
    EXPECT_GT(result.rows[0].cells[0].rmse, 0.0);   // 0.25 against 0.5
    EXPECT_EQ(result.rows[0].cells[1].rmse, 0.0);   // itself
    EXPECT_EQ(result.loc.front().thesis_lines, 7);  // `loc`'s thesis column, declared
}

TEST_F(GreyRegistered, BenchRunsIt) {
    // `bench`'s default list: every registered model that is not Monte Carlo
    // and produces the quantity; then Prepare and Render each.
    std::vector<std::string> picked;
    for (const ModelInfo& info : ListModels()) {
        if (!info.capabilities.stochastic && info.capabilities.radiance) {
            picked.push_back(info.name);
        }
    }
    ASSERT_FALSE(picked.empty());
    EXPECT_EQ(picked.back(), "caps-test-grey");
    std::unique_ptr<Model> model = CreateModel(ParseModelSpec("caps-test-grey:level=0.5"));
    model->Prepare(EarthAtmosphere());
    RenderRequest request =
        atmos_test::QuietRequest(StandardViews(EarthAtmosphere()).front(), 4, 2);
    Image image;
    model->Render(request, &image);
    EXPECT_EQ(image.width(), 4);
}

TEST_F(GreyRegistered, PrepareWarnsOutsideItsDomain) {
    AtmosphereParameters shell = EarthAtmosphere();
    shell.top_radius = 2.0 * shell.bottom_radius;
    std::unique_ptr<Model> model = CreateModel("caps-test-grey");
    ::testing::internal::CaptureStderr();
    model->Prepare(shell);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("model caps-test-grey: outside its valid domain: top/bottom radius ratio 2 "
                       "above 1.5: a test limit"),
              std::string::npos)
        << err;
    ::testing::internal::CaptureStderr();
    model->Prepare(EarthAtmosphere());
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

// Every comparison of a model's name with a string literal ("== \"bruneton\"",
// "\"neural\" != ...") or a list of model names in the layers above the models.
// No std::regex: GCC 12 warns (maybe-uninitialized) inside <regex> under ASan.
bool ComparesAModelName(const std::string& line, const std::vector<std::string>& names) {
    const auto skip_space = [&](size_t i) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        return i;
    };
    const auto skip_space_back = [&](size_t i) {  // i: one past the last character
        while (i > 0 && (line[i - 1] == ' ' || line[i - 1] == '\t')) --i;
        return i;
    };
    const auto literal_at = [&](size_t i) -> size_t {  // length of "name" at i, or 0
        for (const std::string& name : names) {
            const std::string quoted = "\"" + name + "\"";
            if (line.compare(i, quoted.size(), quoted) == 0) return quoted.size();
        }
        return 0;
    };
    for (size_t i = 0; i < line.size(); ++i) {
        const size_t len = literal_at(i);
        if (len == 0) continue;
        const size_t before = skip_space_back(i);
        if (before >= 2 &&
            (line.compare(before - 2, 2, "==") == 0 || line.compare(before - 2, 2, "!=") == 0)) {
            return true;
        }
        size_t after = skip_space(i + len);
        if (line.compare(after, 2, "==") == 0 || line.compare(after, 2, "!=") == 0) return true;
        if (after < line.size() && line[after] == ',' && literal_at(skip_space(after + 1)) > 0) {
            return true;
        }
        const size_t call = line.rfind("StartsWith(", i);
        if (call != std::string::npos && line.find(')', call) > i) return true;
    }
    return false;
}

TEST(Capabilities, NoLayerAboveTheModelsComparesAModelName) {
    const fs::path root = DefaultSourceDir();
    ASSERT_TRUE(fs::is_directory(root / "src" / "atmos" / "models")) << root;
    std::vector<std::string> names;
    for (const ModelInfo& info : ListModels()) names.push_back(info.name);
    EXPECT_TRUE(ComparesAModelName("if (name == \"bruneton\") {", names));
    EXPECT_TRUE(ComparesAModelName("x = \"neural\" != y;", names));
    EXPECT_TRUE(ComparesAModelName("{\"naive\", \"oneil\"}", names));
    EXPECT_TRUE(ComparesAModelName("StartsWith(name, \"neural\")", names));
    EXPECT_FALSE(ComparesAModelName("CreateModel(\"bruneton\");", names));
    std::string found;
    int files = 0;
    for (const char* dir : {"apps", "src/atmos/harness", "src/atmos/render", "python/src"}) {
        if (!fs::is_directory(root / dir)) continue;
        for (const auto& entry : fs::recursive_directory_iterator(root / dir)) {
            const std::string ext = entry.path().extension().string();
            if (ext != ".cpp" && ext != ".h" && ext != ".cu" && ext != ".py") continue;
            ++files;
            std::ifstream in(entry.path());
            std::string line;
            for (int n = 1; std::getline(in, line); ++n) {
                const size_t code = line.find_first_not_of(" \t");
                if (code != std::string::npos && line.compare(code, 2, "//") == 0) continue;
                if (ComparesAModelName(line, names)) {
                    found += entry.path().lexically_relative(root).string() + ":" +
                             std::to_string(n) + ": " + line + "\n";
                }
            }
        }
    }
    EXPECT_GT(files, 20);
    EXPECT_EQ(found, "") << "decide by ModelCapabilities (atmos/model.h), not by the name";
}

}  // namespace
}  // namespace atmos
