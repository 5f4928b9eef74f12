// atmos CLI: `atmos reference-provenance`: the fingerprint of a reference render
// (harness/shipped_references.h), for scripts/make_references.sh: printed,
// checked against a directory of shipped references (which views to render),
// or recorded into its provenance.json.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "cli_common.h"
#include "harness/shipped_references.h"

namespace atmos::cli {

namespace {

struct ProvenanceOptions {
    std::string model = "reference";
    std::string atmosphere = "earth";
    std::vector<std::string> sets;
    std::string size = "320x180";
    std::vector<std::string> views;
    std::string check;
    double noise = 0.0;
    int64_t cap = 0;
    std::string record;
    std::string entry;
};

int CmdReferenceProvenance(const ProvenanceOptions& o) {
    int width = 0, height = 0;
    ParseSize(o.size, &width, &height);
    const ModelSpec spec = ParseModelSpec(o.model);
    if (!GetModelInfo(spec.name).capabilities.stochastic) {
        Fail("reference-provenance: '", spec.name, "' is not a Monte Carlo model");
    }
    const AtmosphereParameters atmosphere = LoadAtmosphere(o.atmosphere, o.sets);
    std::string label = o.atmosphere;
    for (const std::string& s : o.sets) label += " --set " + s;
    std::vector<View> views;
    if (o.views.empty()) {
        views = StandardViews(atmosphere);
    } else {
        for (const std::string& v : o.views) views.push_back(GetView(v, atmosphere));
    }
    const ReferenceFingerprint fingerprint =
        MakeReferenceFingerprint(spec.name, spec.options, label, atmosphere, width, height, views);
    if (!o.check.empty() && !o.record.empty()) Fail("give --check or --record, not both");
    if (!o.record.empty()) {
        if (o.entry.empty()) Fail("--record needs --entry JSON");
        RecordShippedView(o.record, fingerprint, o.entry);
        return 0;
    }
    if (!o.entry.empty()) Fail("--entry goes with --record");
    if (o.check.empty()) {
        std::fputs(ReferenceFingerprintJson(fingerprint).c_str(), stdout);
        return 0;
    }
    // --check: the views whose shipped image does not stand for this render.
    if (!(o.noise >= 0.0 && o.noise < 1.0)) Fail("--noise must be in [0, 1), got ", o.noise);
    if (o.cap < 1) Fail("--check needs --cap N (paths per pixel, >= 1)");
    std::vector<std::string> names;
    for (const View& view : views) names.push_back(view.name);
    for (const ShippedViewCheck& c :
         CheckShippedViews(o.check, fingerprint, names, o.noise, o.cap)) {
        if (c.why.empty()) {
            std::fprintf(stderr, "%s: shipped reference kept (%lld paths per pixel, noise %.4g)\n",
                         c.view.c_str(), static_cast<long long>(c.paths_per_pixel), c.noise);
        } else {
            std::fprintf(stderr, "%s: to render: %s\n", c.view.c_str(), c.why.c_str());
            std::printf("%s\n", c.view.c_str());
        }
    }
    return 0;
}

}  // namespace

Command AddReferenceProvenanceCommand(CLI::App* root) {
    auto o = std::make_shared<ProvenanceOptions>();
    CLI::App* cmd = root->add_subcommand(
        "reference-provenance",
        "the fingerprint of a reference render (shipped references, "
        "scripts/make_references.sh): print it, --check a directory, or --record a view");
    cmd->add_option("--model,-m", o->model, "the Monte Carlo model and its options")
        ->capture_default_str();
    cmd->add_option("--atmosphere,-a", o->atmosphere, "preset name or JSON file")
        ->capture_default_str();
    cmd->add_option("--set", o->sets, "override one atmosphere field: FIELD=VALUE (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--size,-s", o->size, "image size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--views", o->views, "views (default: all 12)")->delimiter(',');
    cmd->add_option("--check", o->check,
                    "a directory of shipped references: print the views whose shipped image "
                    "does not stand for this render (why on stderr)");
    cmd->add_option("--noise", o->noise,
                    "--check: the noise target (a shipped image at or below it is kept)");
    cmd->add_option("--cap", o->cap,
                    "--check: paths per pixel at most (a shipped image with as many is kept)");
    cmd->add_option("--record", o->record,
                    "a directory of shipped references: add --entry to its provenance.json");
    cmd->add_option("--entry", o->entry,
                    "--record: the view's entry, a JSON object with view, paths_per_pixel, "
                    "noise and anything else to keep");
    return {cmd, [o] { return CmdReferenceProvenance(*o); }};
}

}  // namespace atmos::cli
