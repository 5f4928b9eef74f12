#!/usr/bin/env bash
# The reference path tracer's noise floor: for each view and sample count, two
# renders with different seeds, the FLIP (HDR) and RMSE between them, and the
# wall time of one render. Compares the spectral estimator (default) with the
# thesis's (one random channel per path, delta tracking).
# Usage: scripts/reference_noise.sh [SIZE] [SPP list] [VIEWS] > noise.csv
set -euo pipefail
cd "$(dirname "$0")/.."
size="${1:-240x135}"
spps="${2:-16 64 256}"
views="${3:-ground-noon ground-sunrise space}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "view,estimator,spp,size,seconds_per_render,flip,rmse"
for view in $views; do
    for estimator in spectral thesis; do
        for spp in $spps; do
            for seed in 1 2; do
                start=$(date +%s.%N)
                "${ATMOS:-build/atmos}" render --model "reference:estimator=$estimator" --spp "$spp" \
                    --seed "$seed" --view "$view" --size "$size" -q --checkpoint "$tmp/ckpt$seed" \
                    -o "$tmp/$seed.exr"
                end=$(date +%s.%N)
            done
            flip=$("${ATMOS:-build/atmos}" flip "$tmp/1.exr" "$tmp/2.exr" | awk '{v=$NF} END {print v}')
            rmse=$("${ATMOS:-build/atmos}" rmse "$tmp/1.exr" "$tmp/2.exr" | awk '{v=$NF} END {print v}')
            secs=$(echo "$end - $start" | bc -l)
            echo "$view,$estimator,$spp,$size,$secs,$flip,$rmse"
        done
    done
done
