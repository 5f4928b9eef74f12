#!/usr/bin/env bash
# The main job: set up, build, and compare every model against the reference at
# the 12 views: out/index.html (the report), out/flip.csv, out/rmse.csv,
# out/images/, out/errors/. Renders are cached in out/cache, so a second run
# only recomputes what changed. The reference renders each view until the HDR-FLIP between its
# two halves is at or below 0.01 (`--reference-noise`, the default), at most 512 paths per
# pixel (`--reference-spp`); reference_noise.csv says what each view reached. A view whose
# reference is shipped in data/references/WxH (scripts/make_references.sh) with a matching
# provenance is read, not rendered (`--no-shipped-references`: render all). Extra arguments
# go to `atmos compare`, e.g.
#   scripts/run.sh --size 1920x1080 --reference-noise 0.005 --reference-spp 8192   # a full run
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/atmos compare "$@"
echo "open out/index.html"
