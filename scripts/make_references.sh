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
# variance of the mean) and OUT_DIR/provenance.json: the command, the commit
# (and whether the tree had local changes), the model and its estimator
# (`atmos list reference`'s defaults), atmosphere, size, and per view the paths
# per pixel and the noise reached. tests/reference_test.cpp
# (ReferenceShipped.*) renders each shipped image afresh at a few paths and
# checks that the two agree within their standard errors.
# Environment: ATMOS (default build/atmos), MODEL (default reference), SEED
# (default 1).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?usage: scripts/make_references.sh OUT_DIR [SIZE] [NOISE] [CAP] [VIEW...]}"
size="${2:-320x180}"
noise="${3:-0.01}"
cap="${4:-65536}"
shift $(($# < 4 ? $# : 4))
atmos="${ATMOS:-$root/build/atmos}"
model="${MODEL:-reference}"
seed="${SEED:-1}"
views=("$@")
if [ ${#views[@]} -eq 0 ]; then
    views=(ground-dawn ground-sunrise ground-noon plane-dawn plane-sunrise plane-noon orbit-dawn
        orbit-sunrise orbit-noon space planet-shadow-ground planet-shadow-orbit)
fi
mkdir -p "$out"
commit="$(git -C "$root" rev-parse HEAD 2>/dev/null || echo unknown)"
dirty=false
[ -n "$(git -C "$root" status --porcelain --untracked-files=no 2>/dev/null)" ] && dirty=true
entries=()
for v in "${views[@]}"; do
    log="$("$atmos" render --model "$model" --view "$v" --size "$size" --noise "$noise" \
        --spp "$cap" --seed "$seed" -o "$out/$v.exr" 2>&1 >/dev/null)" || {
        echo "$log" >&2
        exit 2
    }
    # The last line for the view: "VIEW: noise X (HDR-FLIP ...) at N paths per pixel ..."
    line="$(echo "$log" | tr '\r' '\n' | grep "^$v: noise" | tail -1 || true)"
    spp="$(echo "$line" | sed -E 's/.* at ([0-9]+) paths per pixel.*/\1/')"
    reached="$(echo "$line" | sed -E 's/^[^:]*: noise ([0-9.eE+-]+).*/\1/')"
    [ -n "$spp" ] && [ -n "$reached" ] || { echo "atmos: error: no noise line for $v" >&2; exit 2; }
    echo "$v: $spp paths per pixel, noise $reached" >&2
    entries+=("    {\"view\": \"$v\", \"paths_per_pixel\": $spp, \"noise\": $reached}")
done
options="$("$atmos" list "$model" --markdown | grep '^| `' | awk -F'|' '{gsub(/ /,"",$2); gsub(/ /,"",$4); printf "%s=%s ", $2, $4}' | tr -d '`')"
{
    echo "{"
    echo "  \"command\": \"scripts/make_references.sh $out $size $noise $cap ${views[*]}\","
    echo "  \"commit\": \"$commit\","
    echo "  \"local_changes\": $dirty,"
    echo "  \"model\": \"$model\","
    echo "  \"options\": \"${options% }\","
    echo "  \"atmosphere\": \"earth\","
    echo "  \"size\": \"$size\","
    echo "  \"noise_target\": $noise,"
    echo "  \"cap\": $cap,"
    echo "  \"seed\": $seed,"
    echo "  \"views\": ["
    n=${#entries[@]}
    for i in "${!entries[@]}"; do
        if [ "$i" -lt $((n - 1)) ]; then echo "${entries[$i]},"; else echo "${entries[$i]}"; fi
    done
    echo "  ]"
    echo "}"
} >"$out/provenance.json"
echo "wrote $out/provenance.json" >&2
