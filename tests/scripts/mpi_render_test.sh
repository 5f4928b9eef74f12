#!/usr/bin/env bash
# Issue 36: `mpirun -np 2 atmos render` writes the bytes one process writes
# (image and variance), and a failure on the ranks is one error, exit 2.
#   tests/scripts/mpi_render_test.sh ATMOS MPIRUN TMP_DIR
# As root (CI), Open MPI needs OMPI_ALLOW_RUN_AS_ROOT=1 and
# OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 (set here); --oversubscribe lets two ranks
# share fewer cores; the shared-memory transport without its single-copy
# mechanism (which containers often forbid: ptrace) keeps stderr clean.
set -euo pipefail
atmos="$1"
mpirun="$2"
tmp="$3"
rm -rf "$tmp"
mkdir -p "$tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
run=("$mpirun" --oversubscribe -np 2)
args=(render -q --model reference --view ground-dawn --size 16x8 --spp 14 --pass-spp 2 --seed 3
    --threads 1)
"$atmos" "${args[@]}" -o "$tmp/one.exr"
"${run[@]}" "$atmos" "${args[@]}" -o "$tmp/mpi.exr"
cmp "$tmp/one.exr" "$tmp/mpi.exr"
cmp "$tmp/one.variance.exr" "$tmp/mpi.variance.exr"
# Each rank's checkpoint is gone once the image is written.
if ls "$tmp"/*.bin >/dev/null 2>&1; then
    echo "checkpoints left behind: $(ls "$tmp")" >&2
    exit 1
fi
# A model that is not Monte Carlo: refused on every rank, exit 2, nothing written.
status=0
"${run[@]}" "$atmos" render -q --model naive --size 16x8 -o "$tmp/naive.exr" \
    2>"$tmp/err.txt" || status=$?
if [ "$status" -ne 2 ] || ! grep -q "atmos: error: mpirun splits the passes of a Monte Carlo" \
    "$tmp/err.txt" || [ -e "$tmp/naive.exr" ]; then
    echo "expected one refusal with exit 2, got $status: $(cat "$tmp/err.txt")" >&2
    exit 1
fi
echo "mpirun -np 2: the same bytes as one process"
