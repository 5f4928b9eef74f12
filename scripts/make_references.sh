#!/usr/bin/env bash
# Renders the path-traced references the project can ship (issue 16 item 4)
# and writes their provenance.
#
#   scripts/make_references.sh OUT_DIR [SIZE] [NOISE] [CAP] [VIEW...]
#
# SIZE (default 320x180), NOISE (the HDR-FLIP between the two halves to reach,
# default 0.01) and CAP (paths per pixel at most, default 65536) go to
# `atmos render --model reference --noise NOISE --spp CAP`; VIEWs default to
# all 12. Writes OUT_DIR/VIEW.exr, OUT_DIR/VIEW.variance.exr (the per-pixel
# variance of the mean) and OUT_DIR/provenance.json (harness/shipped_references.h):
# the fingerprint of what was rendered (`atmos reference-provenance`: estimator
# version, the model with every option resolved, a hash of the resolved
# atmosphere, size, wavelengths, quantity; per view a hash of its camera and
# sun) and per view the paths per pixel, the noise reached, target, cap, seed,
# seconds, backend, commit (and whether the tree had local changes) and this
# command. `atmos compare` reads a view from here instead of rendering it when
# the fingerprint matches its run (data/references/WxH is its default place).
#
# Resumable: a view whose files match the current fingerprint and reached the
# target (or were rendered with at least CAP paths) is skipped; the others are
# rendered (each from its own checkpoint OUT_DIR/.VIEW.partial.bin when an
# interrupted run left one) and recorded one at a time, so a stop loses at
# most the view in progress. tests/reference_test.cpp (ReferenceShipped.*)
# renders each shipped image afresh at a few paths and checks that the two agree
# within their standard errors.
# Environment: ATMOS (default build/atmos), MODEL (default reference),
# ATMOSPHERE (default earth), SEED (default 1), BACKEND (cpu or cuda: `atmos
# render --backend`, default cpu).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?usage: scripts/make_references.sh OUT_DIR [SIZE] [NOISE] [CAP] [VIEW...]}"
size="${2:-320x180}"
noise="${3:-0.01}"
cap="${4:-65536}"
shift $(($# < 4 ? $# : 4))
atmos="${ATMOS:-$root/build/atmos}"
model="${MODEL:-reference}"
atmosphere="${ATMOSPHERE:-earth}"
seed="${SEED:-1}"
backend="${BACKEND:-cpu}"
views=("$@")
if [ ${#views[@]} -eq 0 ]; then
    views=(ground-dawn ground-sunrise ground-noon plane-dawn plane-sunrise plane-noon orbit-dawn
        orbit-sunrise orbit-noon space planet-shadow-ground planet-shadow-orbit)
fi
mkdir -p "$out"
commit="$(git -C "$root" rev-parse HEAD 2>/dev/null || echo unknown)"
dirty=false
[ -n "$(git -C "$root" status --porcelain --untracked-files=no 2>/dev/null)" ] && dirty=true
command="scripts/make_references.sh $out $size $noise $cap ${views[*]}"
fingerprint=(--model "$model" --atmosphere "$atmosphere" --size "$size"
    --views "$(IFS=,; echo "${views[*]}")")
# The views whose shipped files do not stand for this render (why: on stderr).
todo="$("$atmos" reference-provenance "${fingerprint[@]}" --check "$out" --noise "$noise" \
    --cap "$cap")"
for v in $todo; do
    partial="$out/.$v.partial"
    start=$(date +%s)
    log="$("$atmos" render --model "$model" --atmosphere "$atmosphere" --backend "$backend" \
        --view "$v" --size "$size" --noise "$noise" --spp "$cap" --seed "$seed" \
        --checkpoint "$partial" --resume -o "$partial.exr" 2>&1 >/dev/null)" || {
        echo "$log" >&2
        exit 2
    }
    seconds=$(($(date +%s) - start))
    # The last line for the view: "VIEW: noise X (HDR-FLIP ...) at N paths per pixel ..."
    line="$(echo "$log" | tr '\r' '\n' | grep "^$v: noise" | tail -1 || true)"
    spp="$(echo "$line" | sed -E 's/.* at ([0-9]+) paths per pixel.*/\1/')"
    reached="$(echo "$line" | sed -E 's/^[^:]*: noise ([0-9.eE+-]+).*/\1/')"
    [ -n "$spp" ] && [ -n "$reached" ] || { echo "atmos: error: no noise line for $v" >&2; exit 2; }
    mv -f "$partial.exr" "$out/$v.exr"
    mv -f "$partial.variance.exr" "$out/$v.variance.exr"
    "$atmos" reference-provenance "${fingerprint[@]}" --record "$out" --entry "{\"view\": \"$v\", \
\"paths_per_pixel\": $spp, \"noise\": $reached, \"noise_target\": $noise, \"cap\": $cap, \
\"seed\": $seed, \"seconds\": $seconds, \"backend\": \"$backend\", \"commit\": \"$commit\", \
\"local_changes\": $dirty, \"command\": \"$command\"}"
    echo "$v: $spp paths per pixel, noise $reached, $seconds s" >&2
done
echo "$out/provenance.json is up to date" >&2
