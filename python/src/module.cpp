// atmos._atmos: the pybind11 bindings of the library (the Python package
// python/atmos/__init__.py wraps them; docs/python.md is the user's guide).
//
// Everything goes through the same entry points as the command line:
// CreateModel (the model's OptionTable validates keyword options),
// LoadAtmosphere / AtmosphereFromJson, Model::Prepare / Sample / Render, the
// progressive driver for Monte Carlo models, HdrFlip / LdrFlip, ComputeRmse
// and Model::Bake. atmos::Error becomes ValueError with the same message.
// Long calls release the GIL.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/sun_position.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "harness/irradiance.h"
#include "harness/table_cache.h"
#include "metrics/flip.h"
#include "metrics/rmse.h"
#include "render/progressive.h"
#include "render/render.h"

namespace py = pybind11;

namespace atmos {
void BindStudies(py::module_& mod);  // python/src/studies.cpp: validate, compare, bench
namespace {

const char* OptionTypeName(ModelOptionSpec::Type t) {
    switch (t) {
        case ModelOptionSpec::Type::kInteger:
            return "integer";
        case ModelOptionSpec::Type::kReal:
            return "real";
        case ModelOptionSpec::Type::kChoice:
            return "choice";
        case ModelOptionSpec::Type::kText:
            return "text";
    }
    return "?";
}

py::dict InfoDict(const ModelInfo& info) {
    py::dict d;
    d["name"] = info.name;
    d["title"] = info.title;
    d["citation"] = info.citation;
    d["summary"] = info.summary;
    const ModelCapabilities& c = info.capabilities;
    py::dict caps;
    caps["radiance"] = c.radiance;
    caps["transmittance"] = c.transmittance;
    caps["space_views"] = c.space_views;
    caps["sun_below_horizon"] = c.sun_below_horizon;
    caps["multiple_scattering"] = c.multiple_scattering;
    caps["precomputed"] = c.precomputed;
    caps["stochastic"] = c.stochastic;
    caps["spectral"] = c.spectral;
    caps["spectral_paths"] = c.spectral_paths;
    caps["trainable"] = c.trainable;
    caps["shader"] = c.shader;
    caps["validity_notes"] = c.validity_notes;
    d["capabilities"] = caps;
    py::dict domain;  // 0: no limit
    domain["max_radius_ratio"] = info.domain.max_radius_ratio;
    domain["radius_ratio_reason"] = info.domain.radius_ratio_reason;
    domain["max_shell_heights"] = info.domain.max_shell_heights;
    domain["shell_heights_reason"] = info.domain.shell_heights_reason;
    domain["max_radius_heights"] = info.domain.max_radius_heights;
    domain["radius_heights_reason"] = info.domain.radius_heights_reason;
    domain["max_optical_depth"] = info.domain.max_optical_depth;
    domain["optical_depth_reason"] = info.domain.optical_depth_reason;
    d["domain"] = domain;
    py::list options;
    for (const ModelOptionSpec& s : info.options) {
        py::dict o;
        o["name"] = s.name;
        o["type"] = OptionTypeName(s.type);
        o["default"] = s.default_value;
        o["range"] = s.Describe();
        if (s.type == ModelOptionSpec::Type::kInteger || s.type == ModelOptionSpec::Type::kReal) {
            o["min"] = s.min;
            o["max"] = s.max;
        } else {
            o["min"] = py::none();
            o["max"] = py::none();
        }
        o["choices"] = s.choices;
        o["unit"] = s.unit;
        o["help"] = s.help;
        o["shapes_tables"] = s.shapes_tables;
        options.append(o);
    }
    d["options"] = options;
    return d;
}

py::tuple Vec(const Vec3d& v) { return py::make_tuple(v.x, v.y, v.z); }

py::dict ViewDict(const View& v) {
    py::dict d;
    d["name"] = v.name;
    d["description"] = v.description;
    d["position"] = Vec(v.camera.position);
    d["forward"] = Vec(v.camera.forward);
    d["right"] = Vec(v.camera.right);
    d["up"] = Vec(v.camera.up);
    d["vfov_deg"] = 2.0 * std::atan(v.camera.tan_half_fov_y) * 180.0 / kPi;
    d["sun_direction"] = Vec(v.sun_direction);
    d["sun_irradiance"] = v.sun_irradiance;
    d["exposure"] = static_cast<double>(v.exposure);
    return d;
}

// An Image moved into a NumPy array (H x W x 3 float32) without a copy.
py::array_t<float> ImageArray(Image&& image) {
    auto* owned = new Image(std::move(image));
    py::capsule keep(owned, [](void* p) { delete static_cast<Image*>(p); });
    const py::ssize_t h = owned->height(), w = owned->width();
    const py::ssize_t f = static_cast<py::ssize_t>(sizeof(float));
    return py::array_t<float>({h, w, py::ssize_t{3}}, {w * 3 * f, 3 * f, f}, owned->data(), keep);
}

// An H x W x 3 (or H x W: grey) array of numbers as an Image.
Image ArrayImage(const py::array_t<float, py::array::c_style | py::array::forcecast>& a,
                 const char* what) {
    const bool grey = a.ndim() == 2;
    if (a.ndim() == 3 && a.shape(2) != 3) {
        Fail(what, ": expected an H x W x 3 (or H x W) array, got ", a.shape(0), " x ", a.shape(1),
             " x ", a.shape(2), ": ", a.shape(2), " channels, not 3");
    }
    if (!grey && a.ndim() != 3) {
        Fail(what, ": expected an H x W x 3 (or H x W) array, got ", a.ndim(), " dimensions");
    }
    const int h = static_cast<int>(a.shape(0)), w = static_cast<int>(a.shape(1));
    Image image(w, h);
    const float* src = a.data();
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) image.data()[3 * i + c] = grey ? src[i] : src[3 * i + c];
    }
    return image;
}

// A model with the atmosphere of its last prepare().
struct PyModel {
    std::unique_ptr<Model> model;
    std::string spec;  // NAME[:OPTION=VALUE...] as built
    AtmosphereParameters atmosphere;
    bool prepared = false;

    void RequirePrepared() const {
        if (!prepared) Fail("model ", spec, ": call prepare(atmosphere) (or load_baked) first");
    }
};

std::string SpecText(const std::string& name, const std::map<std::string, std::string>& options) {
    std::string text = name;
    for (const auto& [k, v] : options) text += ":" + k + "=" + v;
    return text;
}

PyModel MakeModel(const std::string& name, const std::map<std::string, std::string>& options) {
    PyModel m;
    if (name.find(':') != std::string::npos) {
        ModelSpec spec = ParseModelSpec(name);
        for (const auto& [k, v] : options) {
            if (spec.options.count(k)) Fail("model ", spec.name, ": option ", k, " given twice");
            spec.options[k] = v;
        }
        m.model = CreateModel(spec.name, spec.options);
        m.spec = SpecText(spec.name, spec.options);
    } else {
        m.model = CreateModel(name, options);
        m.spec = SpecText(name, options);
    }
    return m;
}

MonteCarloSettings Settings(const Model& model, py::object spp, py::object seed,
                            py::object pass_spp) {
    const bool given = !spp.is_none() || !seed.is_none() || !pass_spp.is_none();
    if (given && !model.Info().capabilities.stochastic) {
        Fail("spp, seed and pass_spp apply to Monte Carlo models only; model ", model.Info().name,
             " is not one");
    }
    MonteCarloSettings d;
    return MakeMonteCarloSettings(
        spp.is_none() ? d.spp : spp.cast<int64_t>(), seed.is_none() ? 0 : seed.cast<int64_t>(),
        pass_spp.is_none() ? d.pass_spp : pass_spp.cast<int64_t>(), "spp", "seed", "pass_spp");
}

// One argument of sample(): a float64 array read in place through its strides.
struct Operand {
    const char* name;
    const char* base;
    std::vector<py::ssize_t> strides;  // bytes, per output dimension (0: broadcast)
};

// m.sample(altitude, mu, mu_s, azimuth): NumPy broadcasting over the four
// arguments, answers as two float32 arrays of shape broadcast + (3,).
py::tuple Sample(const PyModel& m, const py::array_t<double>& altitude,
                 const py::array_t<double>& mu, const py::array_t<double>& mu_s,
                 const py::array_t<double>& azimuth, py::object spp, py::object seed, bool ground,
                 bool sun_disc) {
    m.RequirePrepared();
    const Model& model = *m.model;
    const bool stochastic = model.Info().capabilities.stochastic;
    const MonteCarloSettings mc = Settings(model, spp, seed, py::none());
    const py::array_t<double>* args[4] = {&altitude, &mu, &mu_s, &azimuth};
    const char* names[4] = {"altitude", "mu", "mu_s", "azimuth"};
    // The broadcast shape (NumPy's rule: align trailing dimensions; 1 stretches).
    py::ssize_t ndim = 0;
    for (const auto* a : args) ndim = std::max(ndim, a->ndim());
    std::vector<py::ssize_t> shape(static_cast<size_t>(ndim), 1);
    for (int k = 0; k < 4; ++k) {
        const py::array_t<double>& a = *args[k];
        for (py::ssize_t d = 0; d < a.ndim(); ++d) {
            const size_t o = static_cast<size_t>(ndim - a.ndim() + d);
            const py::ssize_t n = a.shape(d);
            if (n == shape[o] || n == 1) continue;
            if (shape[o] != 1) {
                std::string s;
                for (int j = 0; j < 4; ++j) {
                    s += std::string(j ? ", " : "") + names[j] + " (";
                    for (py::ssize_t e = 0; e < args[j]->ndim(); ++e) {
                        s += (e ? "," : "") + std::to_string(args[j]->shape(e));
                    }
                    s += ")";
                }
                Fail("sample: shapes do not broadcast: ", s);
            }
            shape[o] = n;
        }
    }
    Operand ops[4];
    for (int k = 0; k < 4; ++k) {
        const py::array_t<double>& a = *args[k];
        ops[k].name = names[k];
        ops[k].base = reinterpret_cast<const char*>(a.data());
        ops[k].strides.assign(static_cast<size_t>(ndim), 0);
        for (py::ssize_t d = 0; d < a.ndim(); ++d) {
            const size_t o = static_cast<size_t>(ndim - a.ndim() + d);
            ops[k].strides[o] = a.shape(d) == 1 ? 0 : a.strides(d);
        }
    }
    py::ssize_t count = 1;
    for (py::ssize_t n : shape) count *= n;
    std::vector<py::ssize_t> out_shape = shape;
    out_shape.push_back(3);
    py::array_t<float> radiance(out_shape), transmittance(out_shape);
    float* l_out = radiance.mutable_data();
    float* t_out = transmittance.mutable_data();

    std::string error;
    {
        py::gil_scoped_release release;
        // Gather the queries (odometer over the broadcast shape), checking each
        // as `atmos sample` does.
        std::vector<SampleQuery> queries(static_cast<size_t>(count));
        std::vector<py::ssize_t> index(static_cast<size_t>(ndim), 0);
        const char* p[4] = {ops[0].base, ops[1].base, ops[2].base, ops[3].base};
        for (py::ssize_t i = 0; i < count && error.empty(); ++i) {
            double v[4];
            for (int k = 0; k < 4; ++k) v[k] = *reinterpret_cast<const double*>(p[k]);
            for (int k = 0; k < 4; ++k) {
                if (!std::isfinite(v[k])) {
                    error = std::string("sample: ") + names[k] + " is not a finite number (" +
                            std::to_string(v[k]) + ") at flat index " + std::to_string(i);
                    break;
                }
            }
            if (error.empty() && v[0] < 0.0) {
                error = "sample: altitude must be >= 0 (at flat index " + std::to_string(i) + ")";
            } else if (error.empty() && (v[1] < -1.0 || v[1] > 1.0)) {
                error = "sample: mu must be in [-1, 1] (at flat index " + std::to_string(i) + ")";
            } else if (error.empty() && (v[2] < -1.0 || v[2] > 1.0)) {
                error = "sample: mu_s must be in [-1, 1] (at flat index " + std::to_string(i) + ")";
            }
            SampleQuery& q = queries[static_cast<size_t>(i)];
            q.altitude_m = v[0];
            q.mu = v[1];
            q.mu_s = v[2];
            q.azimuth_deg = v[3];
            q.ground = ground ? 1 : 0;
            for (py::ssize_t d = ndim - 1; d >= 0; --d) {
                const size_t u = static_cast<size_t>(d);
                for (int k = 0; k < 4; ++k) p[k] += ops[k].strides[u];
                if (++index[u] < shape[u]) break;
                for (int k = 0; k < 4; ++k) p[k] -= ops[k].strides[u] * shape[u];
                index[u] = 0;
            }
        }
        if (error.empty()) {
            std::vector<SampleAnswer> answers =
                stochastic ? SampleMonteCarlo(model, queries, mc) : model.Sample(queries);
            if (sun_disc) AddSunDisc(queries, m.atmosphere, &answers);
            for (size_t i = 0; i < answers.size(); ++i) {
                const SampleAnswer& a = answers[i];
                l_out[3 * i + 0] = a.radiance.x;
                l_out[3 * i + 1] = a.radiance.y;
                l_out[3 * i + 2] = a.radiance.z;
                t_out[3 * i + 0] = a.transmittance.x;
                t_out[3 * i + 1] = a.transmittance.y;
                t_out[3 * i + 2] = a.transmittance.z;
            }
        }
    }
    if (!error.empty()) throw Error(error);
    return py::make_tuple(radiance, transmittance);
}

// Runs f, turning the CLI's flag names in an atmos::Error ("--camera fov ...")
// into the Python argument names ("camera fov ...").
template <typename F>
auto PythonNames(F f) -> decltype(f()) {
    try {
        return f();
    } catch (const Error& e) {
        std::string text = e.what();
        for (const char* flag : {"--camera", "--sun"}) {
            const size_t at = text.find(flag);
            if (at != std::string::npos) text.erase(at, 2);
        }
        throw Error(text);
    }
}

py::object Render(const PyModel& m, const std::string& view_name, int width, int height,
                  const std::string& quantity, bool sun_disc, py::object spp, py::object seed,
                  py::object pass_spp, const std::string& checkpoint, bool resume,
                  bool return_variance, py::object on_pass, const std::string& camera,
                  const std::string& sun) {
    m.RequirePrepared();
    if (width < 1 || width > 16384 || height < 1 || height > 16384) {
        Fail("size (", width, ", ", height, "): each must be in [1, 16384]");
    }
    const Model& model = *m.model;
    const bool stochastic = model.Info().capabilities.stochastic;
    RenderRequest request;
    if (!camera.empty() || !sun.empty()) {
        // A free camera and sun (atmos.Camera, sun=(elevation, azimuth)).
        if (sun.empty()) Fail("sun: a camera needs sun=(elevation_deg, azimuth_deg)");
        const CameraSpec spec = PythonNames([&] { return ParseCameraSpec(camera); });
        PythonNames([&] {
            CheckCameraSpec(spec, width, height);
            return 0;
        });
        const Vec3d direction = PythonNames([&] { return ParseSunSpec(sun); });
        request.view = CustomView(spec, direction, m.atmosphere);
    } else {
        request.view = GetView(view_name, m.atmosphere);
    }
    request.width = width;
    request.height = height;
    request.quantity = ParseQuantity(quantity);
    request.sun_disc = sun_disc;
    request.show_progress = false;
    request.monte_carlo = Settings(model, spp, seed, pass_spp);
    if (!stochastic && (!checkpoint.empty() || resume)) {
        Fail("checkpoint and resume apply to Monte Carlo models only; model ", model.Info().name,
             " is not one");
    }
    request.checkpoint = checkpoint;
    request.resume = resume;
    Image variance;
    if (return_variance) {
        if (!stochastic) Fail("variance: model ", model.Info().name, " is not a Monte Carlo model");
        request.variance = &variance;
    }
    if (!on_pass.is_none()) {
        request.on_pass = [on_pass](int64_t done, int64_t total) {
            py::gil_scoped_acquire acquire;
            on_pass(done, total);  // a Python exception propagates (error_already_set)
        };
    }
    Image image;
    {
        py::gil_scoped_release release;
        model.Render(request, &image);
    }
    if (!stochastic && !on_pass.is_none()) on_pass(1, 1);
    if (return_variance)
        return py::make_tuple(ImageArray(std::move(image)), ImageArray(std::move(variance)));
    return ImageArray(std::move(image));
}

Image ImageArg(const py::object& o, const char* what) {
    if (py::isinstance<py::str>(o)) return ReadImage(o.cast<std::string>());
    return ArrayImage(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(o),
                      what);
}

}  // namespace
}  // namespace atmos

PYBIND11_MODULE(_atmos, mod) {
    using namespace atmos;
    mod.doc() =
        "atmos: sky models, the Monte Carlo reference and image metrics (see docs/python.md)";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });

    mod.def("models", [] {
        std::vector<std::string> names;
        for (const ModelInfo& i : ListModels()) names.push_back(i.name);
        return names;
    });
    mod.def(
        "model_info", [](const std::string& name) { return InfoDict(GetModelInfo(name)); },
        py::arg("name"));
    mod.def("atmosphere_presets", &AtmospherePresetNames);
    mod.def("view_names", &StandardViewNames);
    mod.def(
        "view_info",
        [](const std::string& atmosphere_json) {
            py::list out;
            for (const View& v : StandardViews(AtmosphereFromJson(atmosphere_json))) {
                out.append(ViewDict(v));
            }
            return out;
        },
        py::arg("atmosphere_json"));
    // Atmospheres travel as JSON text (the preset format); parsing validates.
    mod.def(
        "load_atmosphere",
        [](const std::string& name_or_path, const std::vector<std::string>& overrides) {
            return AtmosphereToJson(LoadAtmosphere(name_or_path, overrides));
        },
        py::arg("name_or_path"), py::arg("overrides") = std::vector<std::string>());
    mod.def(
        "atmosphere_from_json",
        [](const std::string& text, const std::string& source) {
            return AtmosphereToJson(AtmosphereFromJson(text, source));
        },
        py::arg("text"), py::arg("source") = "<dict>");

    py::class_<PyModel>(mod, "_Model")
        .def(py::init(&MakeModel), py::arg("name"), py::arg("options"))
        .def_property_readonly("spec", [](const PyModel& m) { return m.spec; })
        .def_property_readonly("name", [](const PyModel& m) { return m.model->Info().name; })
        .def_property_readonly("info", [](const PyModel& m) { return InfoDict(m.model->Info()); })
        .def_property_readonly("prepared", [](const PyModel& m) { return m.prepared; })
        .def("options",
             [](const PyModel& m) {
                 std::map<std::string, std::string> given;
                 const ModelSpec spec = ParseModelSpec(m.spec);
                 return ResolveModelOptions(spec.name, spec.options);
             })
        .def(
            "prepare",
            [](PyModel& m, const std::string& atmosphere_json, bool cache) {
                const AtmosphereParameters a = AtmosphereFromJson(atmosphere_json);
                m.prepared = false;
                bool from_cache = false;
                {
                    // Through the table cache (harness/table_cache.h; issue 33 item 4).
                    const std::map<std::string, std::string> given = ParseModelSpec(m.spec).options;
                    py::gil_scoped_release release;
                    from_cache =
                        PrepareWithTableCache(m.model.get(), given, a, UserTableCache(!cache))
                            .from_cache;
                }
                m.atmosphere = a;
                m.prepared = true;
                return from_cache;
            },
            py::arg("atmosphere_json"), py::arg("cache") = true)
        .def(
            "load_baked",
            [](PyModel& m, const std::string& directory, const std::string& atmosphere_json) {
                const AtmosphereParameters a = AtmosphereFromJson(atmosphere_json);
                m.prepared = false;
                {
                    py::gil_scoped_release release;
                    m.model->LoadBaked(directory, a);
                }
                m.atmosphere = a;
                m.prepared = true;
            },
            py::arg("directory"), py::arg("atmosphere_json"))
        .def("can_bake", [](const PyModel& m) { return m.model->CanBake(); })
        .def(
            "bake",
            [](const PyModel& m, const std::string& directory) {
                m.RequirePrepared();
                if (!m.model->CanBake()) {
                    Fail("model ", m.spec, " has no precomputed tables to bake");
                }
                py::gil_scoped_release release;
                m.model->Bake(directory);
            },
            py::arg("directory"))
        .def("sample", &Sample, py::arg("altitude"), py::arg("mu"), py::arg("mu_s"),
             py::arg("azimuth"), py::arg("spp") = py::none(), py::arg("seed") = py::none(),
             py::arg("ground") = false, py::arg("sun_disc") = false)
        .def("render", &Render, py::arg("view"), py::arg("width"), py::arg("height"),
             py::arg("quantity"), py::arg("sun_disc"), py::arg("spp"), py::arg("seed"),
             py::arg("pass_spp"), py::arg("checkpoint"), py::arg("resume"),
             py::arg("return_variance"), py::arg("on_pass"), py::arg("camera") = "",
             py::arg("sun") = "")
        .def(
            "irradiance",
            [](const PyModel& m, const std::string& sun, double altitude) {
                m.RequirePrepared();
                const Vec3d d = PythonNames([&] { return ParseSunSpec(sun); });
                const double elevation = std::asin(Clamp(d.z, -1.0, 1.0)) * (180.0 / kPi);
                if (!std::isfinite(altitude) || altitude < 0.0) {
                    Fail("altitude must be >= 0 m, got ", altitude);
                }
                HorizontalIrradiance e;
                {
                    py::gil_scoped_release release;
                    e = ComputeHorizontalIrradiance(*m.model, m.atmosphere, altitude, elevation);
                }
                auto rgb = [](const Vec3d& v) { return py::make_tuple(v.x, v.y, v.z); };
                py::dict out;
                out["direct"] = rgb(e.direct);
                out["diffuse"] = rgb(e.diffuse);
                out["diffuse_coarse"] = rgb(e.diffuse_coarse);
                out["nodes"] = py::make_tuple(e.mu_nodes, e.azimuth_nodes);
                out["diffuse_table"] = e.has_table ? py::object(rgb(e.diffuse_table)) : py::none();
                return out;
            },
            py::arg("sun"), py::arg("altitude"));
    mod.def(
        "check_camera",
        [](const std::string& spec) {
            PythonNames([&] {
                CheckCameraSpec(ParseCameraSpec(spec), 0, 0);
                return 0;
            });
        },
        py::arg("spec"));

    mod.def(
        "flip",
        [](const py::object& ref, const py::object& test, bool hdr, double ppd,
           const std::string& tonemapper, py::object start, py::object stop, int num_exposures) {
            CheckFlipPpd(ppd);
            FlipOptions o;
            o.ppd = ppd;
            o.tone_mapper = ParseFlipToneMapper(tonemapper);
            o.has_start_exposure = !start.is_none();
            if (o.has_start_exposure) o.start_exposure = start.cast<double>();
            o.has_stop_exposure = !stop.is_none();
            if (o.has_stop_exposure) o.stop_exposure = stop.cast<double>();
            if (num_exposures < 0) Fail("num_exposures must be >= 0");
            o.num_exposures = num_exposures;
            const Image a = ImageArg(ref, "reference");
            const Image b = ImageArg(test, "test");
            FlipResult r;
            {
                py::gil_scoped_release release;
                r = hdr ? HdrFlip(a, b, o) : LdrFlip(a, b, o);
            }
            py::array_t<float> map(
                {static_cast<py::ssize_t>(r.height), static_cast<py::ssize_t>(r.width)});
            std::copy(r.map.begin(), r.map.end(), map.mutable_data());
            return py::make_tuple(r.mean, map, r.hdr, r.exposures.start, r.exposures.stop,
                                  r.exposures.count);
        },
        py::arg("reference"), py::arg("test"), py::arg("hdr"), py::arg("ppd"),
        py::arg("tonemapper"), py::arg("start_exposure"), py::arg("stop_exposure"),
        py::arg("num_exposures"));
    mod.def(
        "rmse",
        [](const py::object& ref, const py::object& test, double peak) {
            if (!(peak > 0.0) || !std::isfinite(peak)) Fail("peak must be a positive number");
            const RmseResult r = ComputeRmse(ImageArg(ref, "reference"), ImageArg(test, "test"));
            return py::make_tuple(py::make_tuple(r.channel[0], r.channel[1], r.channel[2]),
                                  r.overall, r.mse, Psnr(r.mse, peak));
        },
        py::arg("reference"), py::arg("test"), py::arg("peak"));
    mod.def(
        "read_image", [](const std::string& path) { return ImageArray(ReadImage(path)); },
        py::arg("path"));
    mod.def(
        "write_image",
        [](const py::object& image, const std::string& path, float exposure) {
            WriteImage(ImageArg(image, "image"), path, exposure);
        },
        py::arg("image"), py::arg("path"), py::arg("exposure") = 1.0f);
    mod.def(
        "set_threads",
        [](int threads) {
            // Never destroyed at exit (the scheduler may be gone by then).
            static ThreadLimit* limit = nullptr;
            if (threads < 0) Fail("threads must be >= 0 (0: all cores)");
            delete limit;
            limit = threads > 0 ? new ThreadLimit(threads) : nullptr;
        },
        py::arg("threads"));
    mod.def("thread_count", &ParallelThreadCount);
    // atmos.sun_position (python/atmos/_sun.py): ISO-8601 texts and degrees,
    // flattened and broadcast by the caller; the same parser, range checks and
    // SPA as `atmos sun`. Errors name the argument and the element.
    mod.def(
        "sun_position",
        [](const std::vector<std::string>& times, const std::vector<double>& latitudes,
           const std::vector<double>& longitudes, double height, double pressure,
           double temperature, double delta_t, bool refraction) {
            const size_t n = times.size();
            if (latitudes.size() != n || longitudes.size() != n) {
                Fail("times, latitudes and longitudes must have the same length");
            }
            SunPositionSettings settings;
            settings.delta_t_s = delta_t;
            settings.refraction = refraction;
            settings.pressure_mbar = pressure;
            settings.temperature_c = temperature;
            CheckSunSettings(settings, "sun_position");
            std::vector<double> jd(n);
            std::vector<SunObserver> observers(n);
            for (size_t i = 0; i < n; ++i) {
                const std::string index = "[" + std::to_string(i) + "]";
                jd[i] = ParseIso8601(times[i], "times" + index);
                SunObserver only_latitude;
                only_latitude.latitude_deg = latitudes[i];
                CheckSunObserver(only_latitude, "latitudes" + index);
                SunObserver only_longitude;
                only_longitude.longitude_deg = longitudes[i];
                CheckSunObserver(only_longitude, "longitudes" + index);
                SunObserver only_height;
                only_height.height_m = height;
                CheckSunObserver(only_height, "height");
                observers[i] = {latitudes[i], longitudes[i], height};
            }
            py::array_t<double> elevation(static_cast<py::ssize_t>(n));
            py::array_t<double> azimuth(static_cast<py::ssize_t>(n));
            double* e = elevation.mutable_data();
            double* a = azimuth.mutable_data();
            for (size_t i = 0; i < n; ++i) {
                const SunPosition p = ComputeSunPosition(jd[i], observers[i], settings);
                e[i] = p.elevation_deg;
                a[i] = p.azimuth_deg;
            }
            return py::make_tuple(elevation, azimuth);
        },
        py::arg("times"), py::arg("latitudes"), py::arg("longitudes"), py::arg("height"),
        py::arg("pressure"), py::arg("temperature"), py::arg("delta_t"), py::arg("refraction"));
    mod.attr("__version__") = ATMOS_VERSION;  // the CMake project's (python/CMakeLists.txt)
    BindStudies(mod);
    // The output guard's process-wide count (render/render.h): Model.sample and
    // Model.render warn or raise when a call added to it (issue 39 item 4).
    mod.def("output_guard_count", [] { return OutputGuardCount(); });
    // Tests: guards `nan` NaN values (as a model's defect would), returning the count.
    mod.def("_guard_nan_for_test", [](int nan) {
        std::vector<float> values(static_cast<size_t>(std::max(nan, 0)), std::nanf(""));
        return GuardOutput(values.data(), values.size());
    });
}
