// atmos: shipped path-traced references (issue 16 item 4) and their provenance.
//
// A directory of shipped references holds VIEW.exr (the image), VIEW.variance.exr
// (the per-pixel variance of its mean) and provenance.json, written by
// scripts/make_references.sh through `atmos reference-provenance --record`.
// provenance.json holds the fingerprint of what was rendered, the same for
// every view of the directory, and one entry per view:
//
//   fingerprint: estimator_version (kReferenceEstimatorVersion, bumped when
//     the expected value of `reference`'s images could change), model (the
//     reference's spec with every option resolved, defaults included, e.g.
//     reference:estimator=hybrid:majorant-scale=4:...), atmosphere_hash (FNV-1a
//     64 of the canonical AtmosphereToJson text of the resolved atmosphere: its
//     fields in a fixed order, doubles in the shortest form that reads back
//     exactly), size, wavelengths ("rgb": the atmosphere's three) and quantity
//     ("radiance", no sun disc); atmosphere (the preset or file and the --set
//     overrides) is informative only.
//   views[]: view, view_hash (FNV-1a 64 of ViewFingerprintText: camera frame,
//     field of view, sun direction and irradiance at full precision),
//     paths_per_pixel, noise (the HDR-FLIP between the render's halves), and
//     what the script adds (noise_target, cap, seed, seconds, backend, commit,
//     local_changes, command).
//
// FNV-1a 64 (already the render cache's hash, render_cache.h) guards against
// accidental staleness, not against an adversary; no cryptographic library is
// linked for it.
//
// `compare` uses a shipped image instead of rendering the reference when every
// fingerprint field and the view's hash match the run and the shipped estimate
// is at least as good as the run's own would be (ShippedMismatch).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/view.h"

namespace atmos {

struct ReferenceFingerprint {
    int estimator_version = 0;
    std::string model;            // NAME:OPTION=VALUE:... every option resolved, sorted
    std::string atmosphere;       // informative: preset or file, then the --set overrides
    std::string atmosphere_hash;  // HashText(AtmosphereToJson(resolved atmosphere))
    int width = 0;
    int height = 0;
    std::string wavelengths = "rgb";
    std::string quantity = "radiance";
    std::map<std::string, std::string> view_hashes;  // view name -> HashText(ViewFingerprintText)
};

// "fnv1a64:" and the 16 hex digits of the FNV-1a 64 hash of `text`.
std::string HashText(const std::string& text);
// A view as rendered: its name, camera frame, tangent of the half field of
// view, sun direction and irradiance scale, every number with 17 significant
// digits (the exposure, a PNG setting, is left out).
std::string ViewFingerprintText(const View& view);
// The fingerprint of a reference render of `views` (RGB radiance).
ReferenceFingerprint MakeReferenceFingerprint(const std::string& model,
                                              const std::map<std::string, std::string>& options,
                                              const std::string& atmosphere_label,
                                              const AtmosphereParameters& atmosphere, int width,
                                              int height, const std::vector<View>& views);
// The fingerprint as JSON text (view hashes included), as
// `atmos reference-provenance` prints it.
std::string ReferenceFingerprintJson(const ReferenceFingerprint& fingerprint);

struct ShippedView {
    std::string view;
    std::string view_hash;
    int64_t paths_per_pixel = 0;
    double noise = -1.0;
    std::string commit;  // informative ("" when not recorded)
};

struct ShippedReferences {
    std::string directory;
    ReferenceFingerprint fingerprint;  // view_hashes empty: they are in `views`
    std::vector<ShippedView> views;
    const ShippedView* Find(const std::string& view) const;
};

// Reads DIR/provenance.json; throws atmos::Error naming the file and what is
// wrong (missing, malformed JSON, a missing or mistyped field).
ShippedReferences ReadShippedReferences(const std::string& directory);

// Why the shipped image of `view` cannot stand for the run's reference, or ""
// when it can: every fingerprint field and the view's hash must match `run`,
// and the shipped estimate must be at least as good as the run's would be:
// its noise at or below `noise_target` (when > 0), or at least `spp` paths
// per pixel (the run's cap, or its fixed count): the run could not do better.
// The reasons are joined by "; " (e.g. "atmosphere differs").
std::string ShippedMismatch(const ShippedReferences& shipped, const ReferenceFingerprint& run,
                            const std::string& view, double noise_target, int64_t spp);

// The shipped image and variance of `view` at the run's size (atmos::Error
// when a file is missing, unreadable, of another size or holds a NaN, infinite
// or negative value).
void LoadShippedImages(const ShippedReferences& shipped, const std::string& view, int width,
                       int height, Image* image, Image* variance);

// ShippedMismatch, then LoadShippedImages: the shipped image and variance of
// `view` in `image` and `variance` and "" when they stand for the run's
// reference, else why not (a mismatch, or the load's error; the images are
// left empty).
std::string LoadMatchingShippedView(const ShippedReferences& shipped,
                                    const ReferenceFingerprint& run, const std::string& view,
                                    double noise_target, int64_t spp, Image* image,
                                    Image* variance);

// Which views' shipped images in `directory` stand for the run (`atmos
// reference-provenance --check`): per view, "" when its image is kept, else why
// it must render ("no provenance" when the directory has none; a damaged
// provenance.json is a warning on stderr and every view renders).
struct ShippedViewCheck {
    std::string view;
    std::string why;              // "" : kept
    int64_t paths_per_pixel = 0;  // of a kept image
    double noise = 0.0;
};
std::vector<ShippedViewCheck> CheckShippedViews(const std::string& directory,
                                                const ReferenceFingerprint& run,
                                                const std::vector<std::string>& views,
                                                double noise_target, int64_t spp);

// Adds (or replaces) one view's entry in DIR/provenance.json, written
// atomically: `entry_json` is a JSON object with at least view (one of
// `run`'s views), paths_per_pixel and noise; its view_hash is set from `run`.
// A file with another fingerprint (or none readable) is replaced: its entries
// described other renders.
void RecordShippedView(const std::string& directory, const ReferenceFingerprint& run,
                       const std::string& entry_json);

}  // namespace atmos
