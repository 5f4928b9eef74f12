// atmos studies: custom views of the compare study (`atmos compare --views
// FILE.json`, issue 31 item 5): named cameras and suns, in the vocabulary of
// `render --camera` and `--sun` (atmos/view.h, docs/views.md).
//
// The file is one JSON object whose keys name the views, in order:
//
//   {
//     "plane-sunset": {"camera": "altitude=10000,azimuth=270,elevation=2,fov=50",
//                      "sun": "elevation=1,azimuth=265", "exposure": 8},
//     "all-sky": {"camera": {"projection": "fisheye"},
//                 "sun": {"time": "2024-06-21T05:00:00+02:00", "latitude": 52,
//                         "longitude": 5}}
//   }
//
// camera (required): `--camera`'s KEY=VALUE list as a string, or an object of
// the same keys; sun (required): `--sun`'s, likewise; exposure (optional, > 0,
// default 1): the PNG exposure; description (optional): the report's caption.
// A view is rendered as `render --camera ... --sun ...` renders it: radiance
// per unit solar irradiance, the lit ground below the horizon. Names: letters,
// digits, '.', '_' and '-', none of the 12 named views', each once. Errors name
// the file, the entry and the field.
#pragma once

#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/view.h"

namespace atmos {

struct CompareViewEntry {
    std::string name;
    std::string description;  // empty: CustomView's
    CameraSpec camera;
    Vec3d sun_direction;
    float exposure = 1.0f;
};

// Parses the JSON text of a views file (`label` names it in messages) and
// checks each camera against the image size (equirect 2:1, cubemap 6:1,
// equal-area square). Throws atmos::Error.
std::vector<CompareViewEntry> ParseCompareViews(const std::string& json, const std::string& label,
                                                int width, int height);
// Reads and parses `path`. Throws atmos::Error naming it.
std::vector<CompareViewEntry> ReadCompareViews(const std::string& path, int width, int height);
// A `--views` item that names a views file (it ends in ".json").
bool IsCompareViewsFile(const std::string& item);
// The view of an entry for an atmosphere (CustomView, with the entry's name,
// description and exposure).
View MakeCompareView(const CompareViewEntry& entry, const AtmosphereParameters& atmosphere);

}  // namespace atmos
