// atmos: the command-line tool (contract in DESIGN.md, "The command line").
//
// Every failure prints one line, "atmos: error: ...", on stderr and exits with
// status 2 (usage and input errors) or 1 (anything else unexpected).
#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "harness/gallery.h"

namespace fs = std::filesystem;
using namespace atmos;

namespace {

struct CommonOptions {
    std::string model = "naive";
    std::string atmosphere = "earth";
    std::vector<std::string> sets;
    int threads = 0;
    bool quiet = false;
    // Model options: every option of every model is declared (so --help lists
    // them); after parsing, those given must belong to the chosen model.
    std::map<std::string, std::string> model_option_values;
    std::map<std::string, CLI::Option*> model_option_flags;
};

void AddCommonOptions(CLI::App* cmd, CommonOptions* o) {
    cmd->add_option("--model,-m", o->model, "model name (see `atmos list`)")->capture_default_str();
    cmd->add_option("--atmosphere,-a", o->atmosphere, "preset name or JSON file")
        ->capture_default_str();
    cmd->add_option("--set", o->sets, "override one atmosphere field: FIELD=VALUE (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag("--quiet,-q", o->quiet, "no progress bar or timing lines");
    std::set<std::string> seen;
    for (const ModelInfo& info : ListModels()) {
        for (const ModelOptionSpec& spec : info.options) {
            if (!seen.insert(spec.name).second) continue;
            o->model_option_flags[spec.name] =
                cmd->add_option(
                       "--" + spec.name, o->model_option_values[spec.name],
                       spec.help + " (model " + info.name + ", default " + spec.default_value + ")")
                    ->group("Model options");
        }
    }
}

std::map<std::string, std::string> GivenModelOptions(const CommonOptions& o) {
    std::map<std::string, std::string> given;
    for (const auto& [name, flag] : o.model_option_flags) {
        if (flag->count() > 0) given[name] = o.model_option_values.at(name);
    }
    return given;
}

// "WxH" with 1 <= W, H <= 16384.
void ParseSize(const std::string& text, int* width, int* height) {
    const size_t x = text.find('x');
    auto parse = [&](const std::string& part, int* out) {
        if (part.empty() || part.size() > 6 ||
            part.find_first_not_of("0123456789") != std::string::npos) {
            return false;
        }
        *out = std::stoi(part);
        return *out >= 1 && *out <= 16384;
    };
    if (x == std::string::npos || !parse(text.substr(0, x), width) ||
        !parse(text.substr(x + 1), height)) {
        Fail("malformed size '", text, "': expected WIDTHxHEIGHT, each in [1, 16384]");
    }
}

double Seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

int CmdList() {
    std::printf("models:\n");
    for (const ModelInfo& info : ListModels()) {
        const ModelCapabilities& c = info.capabilities;
        std::printf("  %-16s %s\n", info.name.c_str(), info.title.c_str());
        std::printf("  %-16s   %s\n", "", info.summary.c_str());
        std::printf("  %-16s   source: %s\n", "", info.citation.c_str());
        std::printf(
            "  %-16s   quantities: %s%s%s; space views: %s; sun below horizon: %s; "
            "multiple scattering: %s\n",
            "", c.radiance ? "radiance" : "", c.radiance && c.transmittance ? ", " : "",
            c.transmittance ? "transmittance" : "", c.space_views ? "yes" : "no",
            c.sun_below_horizon ? "yes" : "no", c.multiple_scattering ? "yes" : "no");
        for (const ModelOptionSpec& spec : info.options) {
            std::printf("  %-16s   --%s (default %s): %s\n", "", spec.name.c_str(),
                        spec.default_value.c_str(), spec.help.c_str());
        }
    }
    std::printf("views:\n");
    for (const View& v : StandardViews(EarthAtmosphere())) {
        std::printf("  %-22s exposure %-3g %s\n", v.name.c_str(), static_cast<double>(v.exposure),
                    v.description.c_str());
    }
    std::printf("atmospheres:\n");
    for (const std::string& name : AtmospherePresetNames()) std::printf("  %s\n", name.c_str());
    return 0;
}

struct RenderOptions {
    std::string view = "ground-noon";
    std::string size = "480x270";
    std::string quantity = "radiance";
    std::string output;
    bool sun_disc = false;
    float exposure = 0.0f;  // 0: the view's
};

int CmdRender(const CommonOptions& common, const RenderOptions& ro) {
    int width = 0, height = 0;
    ParseSize(ro.size, &width, &height);
    const Quantity quantity = ParseQuantity(ro.quantity);
    if (ro.output.empty()) Fail("render needs an output: -o FILE (or -o DIR with --view all)");
    const bool all_views = ro.view == "all";
    if (!all_views) ImageFormatFromPath(ro.output);  // fail before the work on a bad name
    if (!std::isfinite(ro.exposure) || ro.exposure < 0.0f) {
        Fail("--exposure must be a positive number");
    }

    ThreadLimit limit(common.threads);
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(common.model, GivenModelOptions(common));
    std::vector<View> views;
    if (all_views) {
        views = StandardViews(atmosphere);
    } else {
        views.push_back(GetView(ro.view, atmosphere));
    }

    const auto prepare_start = std::chrono::steady_clock::now();
    model->Prepare(atmosphere);
    const double prepare_seconds = Seconds(prepare_start);
    if (!common.quiet && prepare_seconds > 0.01) {
        std::fprintf(stderr, "prepared %s in %.3f s\n", common.model.c_str(), prepare_seconds);
    }

    std::vector<GalleryEntry> gallery;
    if (all_views) fs::create_directories(ro.output);
    for (const View& view : views) {
        RenderRequest request;
        request.view = view;
        request.width = width;
        request.height = height;
        request.quantity = quantity;
        request.sun_disc = ro.sun_disc;
        request.show_progress = !common.quiet;
        Image image;
        const auto start = std::chrono::steady_clock::now();
        model->Render(request, &image);
        const double seconds = Seconds(start);
        const float exposure = ro.exposure > 0.0f                ? ro.exposure
                               : quantity == Quantity::kRadiance ? view.exposure
                                                                 : 1.0f;
        if (all_views) {
            const std::string stem = common.model + "-" + view.name;
            WriteImage(image, (fs::path(ro.output) / (stem + ".png")).string(), exposure);
            WriteImage(image, (fs::path(ro.output) / (stem + ".exr")).string(), exposure);
            gallery.push_back(
                {view.name, view.description, stem + ".png", stem + ".exr", seconds, exposure});
        } else {
            WriteImage(image, ro.output, exposure);
        }
        if (!common.quiet) {
            std::fprintf(stderr, "rendered %-22s %dx%d with %s in %.3f s (%d threads)\n",
                         view.name.c_str(), width, height, common.model.c_str(), seconds,
                         ParallelThreadCount());
        }
    }
    if (all_views) {
        const ModelInfo& info = model->Info();
        const std::string page = (fs::path(ro.output) / "index.html").string();
        WriteGalleryHtml(page, "atmos: " + info.title,
                         "model " + info.name + " (" + info.citation + "), atmosphere " +
                             common.atmosphere + ", " + ro.size + ", " + ro.quantity +
                             "; PNG: exposure, 1 - exp(-x), sRGB",
                         gallery);
        if (!common.quiet) std::fprintf(stderr, "wrote %s\n", page.c_str());
    }
    return 0;
}

// Parses one CSV field as a finite number.
double ParseField(const std::string& text, int line, const char* column) {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    const bool ok = !text.empty() && errno == 0 && end == text.c_str() + text.size();
    if (!ok || !std::isfinite(v)) {
        Fail("line ", line, ": ", column, " '", text, "' is not a finite number");
    }
    return v;
}

std::vector<SampleQuery> ReadQueries(std::istream& in) {
    std::vector<SampleQuery> queries;
    std::string line;
    int line_number = 0;
    bool header = false;
    while (std::getline(in, line)) {
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.find_first_not_of(" \t") == std::string::npos) continue;
        if (!header) {
            std::string compact;
            for (char c : line) {
                if (c != ' ' && c != '\t') compact += c;
            }
            if (compact != "altitude_m,mu,mu_s,azimuth_deg") {
                Fail("line ", line_number,
                     ": expected the header 'altitude_m,mu,mu_s,azimuth_deg', got '", line, "'");
            }
            header = true;
            continue;
        }
        std::vector<std::string> fields;
        std::stringstream ss(line);
        std::string field;
        while (std::getline(ss, field, ',')) {
            const size_t b = field.find_first_not_of(" \t");
            const size_t e = field.find_last_not_of(" \t");
            fields.push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
        }
        if (fields.size() != 4) {
            Fail("line ", line_number, ": expected 4 comma-separated numbers, got ", fields.size(),
                 " fields");
        }
        SampleQuery q;
        q.altitude_m = ParseField(fields[0], line_number, "altitude_m");
        q.mu = ParseField(fields[1], line_number, "mu");
        q.mu_s = ParseField(fields[2], line_number, "mu_s");
        q.azimuth_deg = ParseField(fields[3], line_number, "azimuth_deg");
        if (q.altitude_m < 0.0) Fail("line ", line_number, ": altitude_m must be >= 0");
        if (q.mu < -1.0 || q.mu > 1.0) Fail("line ", line_number, ": mu must be in [-1, 1]");
        if (q.mu_s < -1.0 || q.mu_s > 1.0) Fail("line ", line_number, ": mu_s must be in [-1, 1]");
        queries.push_back(q);
    }
    if (!header) Fail("no input: expected the header 'altitude_m,mu,mu_s,azimuth_deg'");
    return queries;
}

int CmdSample(const CommonOptions& common) {
    ThreadLimit limit(common.threads);
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(common.model, GivenModelOptions(common));
    const std::vector<SampleQuery> queries = ReadQueries(std::cin);
    model->Prepare(atmosphere);
    const std::vector<SampleAnswer> answers = model->Sample(queries);
    std::printf("altitude_m,mu,mu_s,azimuth_deg,L_r,L_g,L_b,T_r,T_g,T_b\n");
    for (size_t i = 0; i < queries.size(); ++i) {
        const SampleQuery& q = queries[i];
        const SampleAnswer& a = answers[i];
        std::printf("%.17g,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", q.altitude_m, q.mu,
                    q.mu_s, q.azimuth_deg, static_cast<double>(a.radiance.x),
                    static_cast<double>(a.radiance.y), static_cast<double>(a.radiance.z),
                    static_cast<double>(a.transmittance.x), static_cast<double>(a.transmittance.y),
                    static_cast<double>(a.transmittance.z));
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "atmos: atmospheric scattering models, a path-traced reference and their comparison"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "atmos 0.1.0");

    CLI::App* list = app.add_subcommand("list", "list models, views and atmosphere presets");

    CommonOptions render_common;
    RenderOptions render_options;
    CLI::App* render = app.add_subcommand("render", "render one view (or all) with one model");
    AddCommonOptions(render, &render_common);
    render
        ->add_option("--view,-v", render_options.view,
                     "view name, or 'all' (-o is then a directory)")
        ->capture_default_str();
    render->add_option("--size,-s", render_options.size, "image size WIDTHxHEIGHT")
        ->capture_default_str();
    render->add_option("--quantity", render_options.quantity, "radiance or transmittance")
        ->capture_default_str();
    render->add_flag("--sun-disc", render_options.sun_disc, "add the sun's disc");
    render->add_option("--exposure", render_options.exposure, "PNG exposure (default: the view's)");
    render->add_option("-o,--output", render_options.output,
                       "output file (.exr .png .npy .pfm), or directory with --view all");

    CommonOptions sample_common;
    CLI::App* sample = app.add_subcommand(
        "sample", "evaluate a model at queries read as CSV from stdin, answers to stdout");
    AddCommonOptions(sample, &sample_common);

    try {
        if (argc > 1 && argv[1][0] != '-') {
            bool known = false;
            std::string names;
            for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
                known |= sub->get_name() == argv[1];
                names += (names.empty() ? "" : ", ") + sub->get_name();
            }
            if (!known) Fail("unknown command '", argv[1], "' (commands: ", names, ")");
        }
        app.parse(argc, argv);
        if (list->parsed()) return CmdList();
        if (render->parsed()) return CmdRender(render_common, render_options);
        if (sample->parsed()) return CmdSample(sample_common);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    } catch (const atmos::Error& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
