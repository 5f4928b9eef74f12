#!/usr/bin/env bash
# The main job: set up, build, and compare every model against the reference at
# the 12 views: out/index.html (the report), out/flip.csv, out/rmse.csv,
# out/images/, out/errors/. Renders are cached in out/cache, so a second run
# only recomputes what changed. Extra arguments go to `atmos compare`, e.g.
#   scripts/run.sh --size 1920x1080 --reference-spp 1024     # a full run
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/atmos compare "$@"
echo "open out/index.html"
