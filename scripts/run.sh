#!/usr/bin/env bash
# The main job: set up, build, and render the 12 views with the default model
# into out/ (PNG + EXR per view) with out/index.html showing them.
# Usage: scripts/run.sh [MODEL] [WIDTHxHEIGHT]
set -euo pipefail
cd "$(dirname "$0")/.."
model="${1:-naive}"
size="${2:-960x540}"
scripts/setup.sh
build/atmos render --model "$model" --view all --size "$size" -o out
echo "open out/index.html"
