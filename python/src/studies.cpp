// atmos._atmos: the studies (src/atmos/studies/) as functions returning NumPy
// arrays and dicts: the same config, resolve and run as `atmos validate`,
// `atmos compare` and `atmos bench` (python/atmos/__init__.py wraps them).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "base/parallel.h"
#include "harness/regimes.h"
#include "render/progressive.h"
#include "studies/bench.h"
#include "studies/compare.h"
#include "studies/validate.h"

namespace py = pybind11;

namespace atmos {

namespace {

py::array_t<double> Array2d(const std::vector<double>& v, size_t rows, size_t columns) {
    py::array_t<double> a({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(columns)});
    std::copy(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rows * columns), a.mutable_data());
    return a;
}

py::dict ValidateDict(const ValidateResult& r) {
    py::dict d;
    d["wavelengths"] = py::array_t<double>(static_cast<py::ssize_t>(r.nm.size()), r.nm.data());
    py::list captures;
    std::vector<double> measured;
    std::vector<int> sample;
    for (const KiderSample& s : r.samples) {
        captures.append(s.capture);
        sample.push_back(s.sample);
        measured.insert(measured.end(), s.spectrum, s.spectrum + kKiderBins);
    }
    d["capture"] = captures;
    d["sample"] = py::array_t<int>(static_cast<py::ssize_t>(sample.size()), sample.data());
    d["measured"] = Array2d(measured, r.samples.size(), kKiderBins);
    py::dict models;
    for (const ValidateModelResult& m : r.models) {
        py::list errors;
        for (const ValidateErrorRow& row : m.rows) {
            py::dict e;
            e["capture"] = row.capture;
            e["scope"] = row.scope;
            e["region"] = row.region;
            e["relative_rmse"] = row.error.RelativeRmse();
            e["absolute_rmse"] = row.error.AbsoluteRmse();
            e["count"] = row.error.count;
            e["mean_model"] = row.model_sum / std::max(1L, row.error.count);
            e["mean_measured"] = row.error.measured / std::max(1L, row.error.count);
            errors.append(e);
        }
        py::dict md;
        md["values"] = Array2d(m.values, r.samples.size(), r.nm.size());
        md["errors"] = errors;
        md["seconds"] = m.seconds;
        models[py::str(m.model)] = md;
    }
    d["models"] = models;
    d["sets"] = r.sets;
    if (r.fitted) {
        py::dict fit;
        for (int i = 0; i < r.fit.count; ++i) fit[kAerosolParameters[i].name] = r.fit.values[i];
        fit["residual"] = r.fit.residual;
        fit["start_residual"] = r.fit.start_residual;
        fit["evaluations"] = r.fit.evaluations;
        fit["stop"] = r.fit.stop;
        d["fit"] = fit;
    } else {
        d["fit"] = py::none();
    }
    d["errors_csv"] = ValidateErrorsCsv(r);
    return d;
}

py::dict CompareDict(const CompareConfig& config, const CompareResult& r) {
    py::dict d;
    d["models"] = r.models;
    d["reference"] = config.reference_model;
    d["output_dir"] = config.output_dir;
    std::vector<std::string> views;
    std::vector<double> flip, rmse, noise, flip_sky, flip_ground, rmse_sky, rmse_ground, lum,
        ref_lum;
    std::vector<int64_t> spp;
    for (const CompareRow& row : r.rows) {
        views.push_back(row.view);
        noise.push_back(row.reference_noise);
        spp.push_back(row.reference_spp);
        ref_lum.push_back(row.reference_luminance.all);
        for (const CompareCell& c : row.cells) {
            flip.push_back(c.flip);
            rmse.push_back(c.rmse);
            flip_sky.push_back(c.flip_sky);
            flip_ground.push_back(c.flip_ground);
            rmse_sky.push_back(c.rmse_sky);
            rmse_ground.push_back(c.rmse_ground);
            lum.push_back(c.luminance.all);
        }
    }
    const size_t nv = r.rows.size(), nm = r.models.size();
    d["flip_sky"] = Array2d(flip_sky, nv, nm);
    d["flip_ground"] = Array2d(flip_ground, nv, nm);
    d["rmse_sky"] = Array2d(rmse_sky, nv, nm);
    d["rmse_ground"] = Array2d(rmse_ground, nv, nm);
    if (config.luminance) {
        d["luminance"] = Array2d(lum, nv, nm);
        d["reference_luminance"] =
            py::array_t<double>(static_cast<py::ssize_t>(ref_lum.size()), ref_lum.data());
    }
    py::list regimes;
    for (const RegimeVerdict& v : JudgeRegimes(r)) {
        py::dict e;
        e["kind"] = v.kind;
        e["regime"] = v.regime;
        e["views"] = v.views;
        std::vector<std::string> best;
        for (int m : v.best) best.push_back(r.models[static_cast<size_t>(m)]);
        e["best"] = best;
        e["flip"] = v.flip;
        e["frame_seconds"] = v.frame_seconds;
        e["precompute_seconds"] = v.precompute_seconds;
        e["machine"] = CostMachine(config, r);
        e["reference_noise"] = v.reference_noise;
        e["excluded"] = v.excluded;
        regimes.append(e);
    }
    d["regimes"] = regimes;
    d["views"] = views;
    d["flip"] = Array2d(flip, r.rows.size(), r.models.size());
    d["rmse"] = Array2d(rmse, r.rows.size(), r.models.size());
    d["reference_noise"] =
        py::array_t<double>(static_cast<py::ssize_t>(noise.size()), noise.data());
    d["reference_spp"] = py::array_t<int64_t>(static_cast<py::ssize_t>(spp.size()), spp.data());
    return d;
}

// One dict per item (its "model" and "view", then what `fill` adds), as a list.
template <typename T, typename F>
py::list ModelViewDicts(const std::vector<T>& items, F fill) {
    py::list out;
    for (const T& item : items) {
        py::dict e;
        e["model"] = item.model;
        e["view"] = item.view;
        fill(item, e);
        out.append(e);
    }
    return out;
}

py::dict BenchDict(const BenchResult& r) {
    py::dict d;
    const py::list rows = ModelViewDicts(r.rows, [](const BenchRow& b, py::dict& e) {
        e["prepare_s"] = b.prepare_s;
        e["render_median_s"] = b.render_median_s;
        e["render_min_s"] = b.render_min_s;
        e["render_max_s"] = b.render_max_s;
        e["runs"] = b.runs;
        e["megapixels_per_s"] = b.megapixels_per_s;
        e["paths_per_s"] = b.paths_per_s;
    });
    const py::list stages = ModelViewDicts(r.stages, [](const BenchStage& s, py::dict& e) {
        e["stage"] = s.name;
        e["items"] = s.items;
        e["runs"] = s.runs;
        e["kernel_median_ms"] = s.kernel_median_ms;
        e["total_median_ms"] = s.total_median_ms;
    });
    const py::list spectral =
        ModelViewDicts(r.spectral_rows, [](const BenchSpectralRow& s, py::dict& e) {
            e["wavelengths"] = s.wavelengths;
            e["rgb_prepare_s"] = s.rgb_prepare_s;
            e["rgb_render_s"] = s.rgb_render_s;
            e["spectral_prepare_s"] = s.spectral_prepare_s;
            e["spectral_render_s"] = s.spectral_render_s;
        });
    d["rows"] = rows;
    d["stages"] = stages;
    d["spectral"] = spectral;
    d["threads"] = r.threads;
    d["backend"] = r.backend;
    d["csv"] = r.spectral_rows.empty() ? BenchCsv(r) : BenchSpectralCsv(r);
    return d;
}

}  // namespace

void BindStudies(py::module_& mod) {
    mod.def(
        "validate",
        [](const std::vector<std::string>& models, const std::string& data,
           const std::string& atmosphere, const std::vector<std::string>& sets,
           const std::vector<std::string>& captures, bool theory_azimuth, int64_t spp, int64_t seed,
           bool fit, const std::string& fit_model, std::vector<double> fit_nm,
           const std::vector<std::string>& fit_captures, int fit_evaluations,
           bool fit_second_lobe) {
            ValidateConfig c;
            if (!models.empty()) c.models = models;
            if (!data.empty()) c.data_dir = data;
            if (!atmosphere.empty()) c.atmosphere = atmosphere;
            c.sets = sets;
            c.captures = captures;
            c.theory_azimuth = theory_azimuth;
            c.spp = spp;
            c.seed = seed;
            c.fit = fit;
            if (!fit_model.empty()) c.fit_model = fit_model;
            if (!fit_nm.empty()) c.fit_nm = fit_nm;
            c.fit_captures = fit_captures;
            c.fit_evaluations = fit_evaluations;
            c.fit_second_lobe = fit_second_lobe;
            c = ResolveValidateConfig(c);
            ValidateResult r;
            {
                py::gil_scoped_release release;
                r = RunValidate(c, ReadValidateData(c));
            }
            return ValidateDict(r);
        },
        py::arg("models"), py::arg("data"), py::arg("atmosphere"), py::arg("sets"),
        py::arg("captures"), py::arg("theory_azimuth"), py::arg("spp"), py::arg("seed"),
        py::arg("fit"), py::arg("fit_model"), py::arg("fit_wavelengths"), py::arg("fit_captures"),
        py::arg("fit_evaluations"), py::arg("fit_second_lobe"));
    mod.def(
        "compare",
        [](const std::vector<std::string>& models, const std::vector<std::string>& views,
           const std::string& views_json, int width, int height, const std::string& quantity,
           std::optional<std::string> reference, std::optional<int64_t> reference_spp,
           std::optional<int64_t> reference_seed, std::optional<double> reference_noise,
           const std::string& atmosphere, const std::vector<std::string>& sets,
           const std::string& output_dir, std::optional<std::string> cache_dir, bool no_cache,
           bool shipped_references, bool write_npy, bool progress, bool luminance) {
            CompareRequest q;
            q.models = models;
            q.views = views;
            q.views_json = views_json;
            q.width = width;
            q.height = height;
            q.quantity = quantity;
            q.reference = reference;
            q.reference_spp = reference_spp;
            q.reference_seed = reference_seed;
            q.reference_noise = reference_noise;
            q.atmosphere = atmosphere;
            q.sets = sets;
            q.output_dir = output_dir;
            q.cache_dir = cache_dir;
            q.no_cache = no_cache;
            q.no_shipped = !shipped_references;
            q.write_npy = write_npy;
            q.show_progress = progress;
            q.luminance = luminance;
            q.command_line = "atmos.compare (Python)";
            const CompareConfig config = ResolveCompareConfig(q);
            CompareResult r;
            {
                py::gil_scoped_release release;
                r = RunCompare(config);
                WriteCompareImages(config, r);
                WriteCompareTables(config, r);
            }
            return CompareDict(config, r);
        },
        py::arg("models"), py::arg("views"), py::arg("views_json"), py::arg("width"),
        py::arg("height"), py::arg("quantity"), py::arg("reference"), py::arg("reference_spp"),
        py::arg("reference_seed"), py::arg("reference_noise"), py::arg("atmosphere"),
        py::arg("sets"), py::arg("output_dir"), py::arg("cache_dir"), py::arg("no_cache"),
        py::arg("shipped_references"), py::arg("write_npy"), py::arg("progress"),
        py::arg("luminance"));
    mod.def(
        "bench",
        [](const std::vector<std::string>& models, const std::vector<std::string>& views, int width,
           int height, const std::string& quantity, std::optional<int> repeat,
           std::optional<int> warmup, int prepare_repeat, const std::string& atmosphere,
           const std::vector<std::string>& sets, std::optional<int64_t> spp, int64_t seed,
           const std::vector<double>& wavelengths) {
            BenchConfig c;
            c.models = models;
            c.views = views;
            c.width = width;
            c.height = height;
            c.quantity = quantity;
            c.repeat = repeat;
            c.warmup = warmup;
            c.prepare_repeat = prepare_repeat;
            c.atmosphere = atmosphere;
            c.sets = sets;
            c.monte_carlo_given = spp.has_value() || seed != 0;
            c.monte_carlo = MakeMonteCarloSettings(spp.value_or(64), seed, 0, "spp", "seed");
            c.wavelengths = wavelengths;
            c = ResolveBenchConfig(c);
            BenchResult r;
            {
                py::gil_scoped_release release;
                r = RunBench(c);
            }
            return BenchDict(r);
        },
        py::arg("models"), py::arg("views"), py::arg("width"), py::arg("height"),
        py::arg("quantity"), py::arg("repeat"), py::arg("warmup"), py::arg("prepare_repeat"),
        py::arg("atmosphere"), py::arg("sets"), py::arg("spp"), py::arg("seed"),
        py::arg("wavelengths"));
}

}  // namespace atmos
