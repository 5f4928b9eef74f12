// atmos: the verdict per regime of `atmos compare` (regimes.h).
#include "harness/regimes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "atmos/error.h"
#include "harness/ranking.h"
#include "io/output_path.h"

namespace atmos {

namespace {

constexpr double kGroundAltitudeM = 1000.0;
constexpr double kDayElevationDeg = 10.0;

std::string Number(double v) {
    if (!std::isfinite(v)) return "";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

}  // namespace

const std::vector<std::string>& PlaceRegimes() {
    static const std::vector<std::string> v = {"ground", "aircraft", "orbit", "space"};
    return v;
}

const std::vector<std::string>& LightRegimes() {
    static const std::vector<std::string> v = {"day", "sunrise", "twilight", "planet shadow"};
    return v;
}

std::string PlaceRegime(const View& view, const AtmosphereParameters& atmosphere) {
    const double altitude = Length(view.camera.position) - atmosphere.bottom_radius;
    if (altitude < kGroundAltitudeM) return "ground";
    if (altitude < atmosphere.top_radius - atmosphere.bottom_radius) return "aircraft";
    if (altitude < atmosphere.bottom_radius) return "orbit";
    return "space";
}

std::string LightRegime(const View& view, const AtmosphereParameters& atmosphere) {
    const Vec3d p = view.camera.position;
    Vec3d q = p;  // the point whose zenith measures the sun's elevation
    const Vec3d d = Normalize(view.camera.forward);
    if (view.camera.projection == Projection::kPerspective) {
        const double b = Dot(p, d);
        const double c = Dot(p, p) - atmosphere.bottom_radius * atmosphere.bottom_radius;
        double t = std::max(0.0, -b);  // nearest the centre
        if (b < 0.0 && c > 0.0 && b * b - c >= 0.0) t = -b - std::sqrt(b * b - c);  // the ground
        q = p + d * t;
    }
    const Vec3d up = Normalize(q);
    const Vec3d sun = Normalize(view.sun_direction);
    const double elevation = std::asin(std::clamp(Dot(sun, up), -1.0, 1.0)) * 180.0 / kPi;
    if (elevation >= kDayElevationDeg) return "day";
    if (elevation >= 0.0) return "sunrise";
    if (view.camera.projection != Projection::kPerspective) return "twilight";
    const Vec3d sun_h = sun - up * Dot(sun, up);
    const Vec3d look_h = d - up * Dot(d, up);
    return Dot(sun_h, look_h) >= 0.0 ? "twilight" : "planet shadow";
}

std::vector<RegimeVerdict> JudgeRegimes(const CompareResult& r) {
    std::vector<RegimeVerdict> out;
    const size_t models = r.models.size();
    for (const char* kind : {"place", "light"}) {
        const bool place = std::string(kind) == "place";
        for (const std::string& regime : place ? PlaceRegimes() : LightRegimes()) {
            std::vector<size_t> rows;
            for (size_t i = 0; i < r.rows.size(); ++i) {
                if ((place ? r.rows[i].place : r.rows[i].light) == regime) rows.push_back(i);
            }
            if (rows.empty()) continue;
            RegimeVerdict v;
            v.kind = kind;
            v.regime = regime;
            double noise = 0.0;
            for (size_t i : rows) {
                v.views.push_back(r.rows[i].label);
                if (r.rows[i].reference_noise < 0.0) noise = -INFINITY;
                noise += r.rows[i].reference_noise;
            }
            v.reference_noise =
                std::isfinite(noise) ? noise / static_cast<double>(rows.size()) : -1.0;
            std::vector<double> mean(models, std::nan("")), seconds(models, 0.0);
            for (size_t m = 0; m < models; ++m) {
                bool baseline = false;
                try {
                    baseline = GetModelInfo(r.model_names[m]).capabilities.baseline;
                } catch (const Error&) {
                }
                std::string outside;
                double sum = 0.0;
                for (size_t i : rows) {
                    const CompareCell& c = r.rows[i].cells[m];
                    sum += c.flip;
                    seconds[m] += c.render_seconds / static_cast<double>(rows.size());
                    if (!c.validity_note.empty() && outside.empty()) outside = r.rows[i].label;
                }
                if (baseline) {
                    v.excluded.push_back(r.models[m] + " (a baseline)");
                } else if (!outside.empty()) {
                    v.excluded.push_back(r.models[m] + " (outside its validity: " + outside + ")");
                } else {
                    mean[m] = sum / static_cast<double>(rows.size());
                }
            }
            v.best = BestOfRow(mean, v.reference_noise);
            std::stable_sort(v.best.begin(), v.best.end(),
                             [&](int a, int b) { return mean[a] < mean[b]; });
            for (int m : v.best) {
                const size_t k = static_cast<size_t>(m);
                v.flip.push_back(mean[k]);
                v.frame_seconds.push_back(seconds[k]);
                bool precomputed = false;
                try {
                    precomputed = GetModelInfo(r.model_names[k]).capabilities.precomputed;
                } catch (const Error&) {
                }
                v.precompute_seconds.push_back(
                    precomputed && k < r.prepare_seconds.size() ? r.prepare_seconds[k] : 0.0);
            }
            out.push_back(v);
        }
    }
    return out;
}

std::string CostMachine(const CompareConfig& config, const CompareResult& r) {
    if (config.machine != "CPU") return config.machine;
    return "CPU, " + std::to_string(r.threads) + " threads";
}

void WriteRegimesCsv(const std::string& path, const CompareConfig& config, const CompareResult& r) {
    TextOutput f(path);
    f << "kind,regime,views,best,flip,frame_seconds,precompute_seconds,machine,reference_noise,"
         "excluded\n";
    for (const RegimeVerdict& v : JudgeRegimes(r)) {
        auto join = [](const std::vector<std::string>& items) {
            std::string s;
            for (const std::string& i : items) s += (s.empty() ? "" : " ") + i;
            return s;
        };
        std::vector<std::string> best, flip, frame, pre;
        for (size_t k = 0; k < v.best.size(); ++k) {
            best.push_back(r.models[static_cast<size_t>(v.best[k])]);
            flip.push_back(Number(v.flip[k]));
            frame.push_back(Number(v.frame_seconds[k]));
            pre.push_back(Number(v.precompute_seconds[k]));
        }
        std::string excluded = join(v.excluded);
        for (char& c : excluded) c = c == ',' ? ';' : c;
        std::string machine = CostMachine(config, r);
        for (char& c : machine) c = c == ',' ? ';' : c;
        f << v.kind << "," << v.regime << "," << join(v.views) << "," << join(best) << ","
          << join(flip) << "," << join(frame) << "," << join(pre) << "," << machine << ","
          << (v.reference_noise >= 0.0 ? Number(v.reference_noise) : "") << ",\"" << excluded
          << "\"\n";
    }
    f.Commit();
}

}  // namespace atmos
