// atmos studies: custom views of the compare study (compare_views.h).
#include "studies/compare_views.h"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "io/bounded_read.h"

namespace atmos {

namespace {

constexpr size_t kMaxViewsFileBytes = size_t{16} << 20;

// A camera or sun field as `--camera`/`--sun` text: a string as it is, an
// object as KEY=VALUE pairs in its order.
std::string SpecText(const nlohmann::ordered_json& value, const std::string& where) {
    if (value.is_string()) return value.get<std::string>();
    if (!value.is_object()) {
        Fail(where, " must be a KEY=VALUE[,KEY=VALUE...] string or an object of keys");
    }
    std::string text;
    for (const auto& [key, v] : value.items()) {
        std::string s;
        if (v.is_string()) {
            s = v.get<std::string>();
        } else if (v.is_number()) {
            s = v.dump();
        } else {
            Fail(where, ": ", key, " must be a number or a string, got ", v.dump());
        }
        text += (text.empty() ? "" : ",") + key + "=" + s;
    }
    return text;
}

// Runs `parse`, prefixing its error with `where` (and dropping the flag's
// name, which the file does not use).
template <typename F>
auto Within(const std::string& where, const char* flag, F parse) -> decltype(parse()) {
    try {
        return parse();
    } catch (const Error& e) {
        std::string message = e.what();
        const std::string f = flag;
        if (message.rfind(f, 0) == 0) {
            message = message.substr(f.size());
            while (!message.empty() && (message[0] == ' ' || message[0] == ':')) {
                message.erase(0, 1);
            }
        }
        Fail(where, ": ", message);
    }
}

bool ValidName(const std::string& name) {
    if (name.empty()) return false;
    for (char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                        (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
        if (!ok) return false;
    }
    return true;
}

}  // namespace

bool IsCompareViewsFile(const std::string& item) {
    return item.size() > 5 && item.compare(item.size() - 5, 5, ".json") == 0;
}

std::vector<CompareViewEntry> ParseCompareViews(const std::string& json, const std::string& label,
                                                int width, int height) {
    nlohmann::ordered_json doc;
    try {
        doc = nlohmann::ordered_json::parse(json);
    } catch (const nlohmann::json::exception& e) {
        Fail(label, ": not valid JSON (", e.what(), ")");
    }
    if (!doc.is_object() || doc.empty()) {
        Fail(label,
             ": expected a JSON object of named views, {\"NAME\": {\"camera\": ..., \"sun\": "
             "...}, ...}");
    }
    const std::vector<std::string> standard = StandardViewNames();
    std::vector<CompareViewEntry> out;
    for (const auto& [name, value] : doc.items()) {
        const std::string where = label + ": view '" + name + "'";
        if (!ValidName(name)) {
            Fail(where, ": a name holds letters, digits, '.', '_' and '-' only");
        }
        for (const std::string& s : standard) {
            if (s == name) Fail(where, ": the name of one of the 12 named views (choose another)");
        }
        if (!value.is_object()) Fail(where, ": expected an object {\"camera\": ..., \"sun\": ...}");
        for (const auto& [field, unused] : value.items()) {
            (void)unused;
            if (field != "camera" && field != "sun" && field != "exposure" &&
                field != "description") {
                Fail(where, ": unknown field '", field,
                     "' (fields: camera, sun, exposure, description)");
            }
        }
        CompareViewEntry e;
        e.name = name;
        if (!value.contains("camera")) Fail(where, ": camera is missing");
        if (!value.contains("sun")) Fail(where, ": sun is missing");
        const std::string camera_where = where + ", camera";
        const std::string camera = SpecText(value["camera"], camera_where);
        e.camera = Within(camera_where, "--camera", [&] { return ParseCameraSpec(camera); });
        Within(camera_where, "--camera", [&] {
            CheckCameraSpec(e.camera, width, height);
            return 0;
        });
        const std::string sun_where = where + ", sun";
        const std::string sun = SpecText(value["sun"], sun_where);
        e.sun_direction = Within(sun_where, "--sun", [&] { return ParseSunSpec(sun); });
        if (value.contains("exposure")) {
            const auto& x = value["exposure"];
            if (!x.is_number() || !(x.get<double>() > 0.0) || !(x.get<double>() < 1e30)) {
                Fail(where, ", exposure must be a number > 0, got ", x.dump());
            }
            e.exposure = static_cast<float>(x.get<double>());
        }
        if (value.contains("description")) {
            if (!value["description"].is_string()) {
                Fail(where, ", description must be a string");
            }
            e.description = value["description"].get<std::string>();
        }
        out.push_back(e);
    }
    return out;
}

std::vector<CompareViewEntry> ReadCompareViews(const std::string& path, int width, int height) {
    return ParseCompareViews(ReadFileBounded(path, kMaxViewsFileBytes), path, width, height);
}

View MakeCompareView(const CompareViewEntry& entry, const AtmosphereParameters& atmosphere) {
    View v = CustomView(entry.camera, entry.sun_direction, atmosphere);
    v.name = entry.name;
    if (!entry.description.empty()) v.description = entry.description;
    v.exposure = entry.exposure;
    return v;
}

}  // namespace atmos
