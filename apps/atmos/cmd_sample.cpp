// atmos CLI: `atmos sample`.
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/number.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "harness/gallery.h"
#include "render/progressive.h"
#include "sample_spectral.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

// Parses one CSV field as a finite number.
double ParseField(const std::string& text, int line, const char* column) {
    double v = 0.0;
    const NumberError e = ParseNumber(text, &v);  // atmos/number.h: the one parser
    if (e != NumberError::kNone)
        Fail("line ", line, ": ", column, " '", text, "' ", NumberErrorText(e));
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

int CmdSample(const CommonOptions& common, const MonteCarloFlags& flags,
              const SpectralFlags& spectral) {
    ThreadLimit limit(common.threads);
    const BackendScope backend(ParseBackend(common.backend));
    if (!spectral.wavelengths.empty()) {
        ParseWavelengths(spectral.wavelengths);  // fail before reading stdin
        const MonteCarloSettings mc = flags.Settings(CreateModel(GivenModel(common))->Info());
        return SampleSpectralCsv(common, mc, spectral.wavelengths, ReadQueries(std::cin));
    }
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(GivenModel(common));
    const MonteCarloSettings monte_carlo = flags.Settings(model->Info());
    const std::vector<SampleQuery> queries = ReadQueries(std::cin);
    PrepareModel(common, atmosphere, model.get());
    const std::vector<SampleAnswer> answers = model->Info().capabilities.stochastic
                                                  ? SampleMonteCarlo(*model, queries, monte_carlo)
                                                  : model->Sample(queries);
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

Command AddSampleCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto flags = std::make_shared<MonteCarloFlags>();
    auto spectral = std::make_shared<SpectralFlags>();
    Command c;
    c.app = root->add_subcommand(
        "sample", "evaluate a model at queries read as CSV from stdin, answers to stdout");
    AddCommonOptions(c.app, common.get());
    AddBackendOption(c.app, &common->backend);
    AddMonteCarloFlags(c.app, flags.get());
    AddSpectralFlags(c.app, spectral.get(), false);
    c.run = [common, flags, spectral] { return CmdSample(*common, *flags, *spectral); };
    return c;
}

}  // namespace atmos::cli
