#!/usr/bin/env bash
# Runs the GPU checks of issue 10 on a machine with an NVIDIA GPU, from the
# bundle scripts/gpu_bundle.sh made (.gpu/). Each phase writes its log and
# CSVs under $OUT (the device tool's output folder; default out/gpu) and the
# whole folder is also packed into $OUT/gpu_results.tar.gz.
#
# Usage: scripts/gpu_check.sh PHASE...   phases, in the order given:
#   info       nvidia-smi, the bundle's commit, `atmos list`
#   tests      the CUDA parity / precompute / backend tests (gtest XML)
#   sanitize   compute-sanitizer memcheck and racecheck on the parity tests
#   bench      atmos bench --backend cuda: every model and view at 1920x1080,
#              median of 256 kernel launches after 16; Prepare() 5 times
#   cpu-bench  the same models on this machine's CPU cores (for the ratio)
#   paths      the path tracer's paths per second per view (1920x1080, 64 spp)
#   roofline   Nsight Compute counters of one render kernel per model (VIEW,
#              default ground-noon, at SIZE) and scripts/roofline.py's table
#              (FLOPs and DRAM bytes per pixel, rates at the bench's medians:
#              run `bench` first in the same $OUT)
#   noise      reference noise floor at 1920x1080 (two seeds, HDR-FLIP between
#              them) for NOISE_VIEWS (default ground-noon) at NOISE_SPP
#   all        info tests sanitize bench paths
# Environment: SIZE (default 1920x1080), REPEAT (256), MODELS (all but the
# reference), NOISE_VIEWS, NOISE_SPP (default "1024 4096").
set -uo pipefail
cd "$(dirname "$0")/.."
OUT="${OUT:-out/gpu}"
mkdir -p "$OUT"
B=.gpu
if [ ! -x "$B/atmos" ]; then
    echo "gpu_check: no bundle in $B/ (run scripts/gpu_bundle.sh on the build machine)" >&2
    exit 2
fi
export LD_LIBRARY_PATH="$PWD/$B/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
if ! "$B/atmos" list >/dev/null 2>&1; then  # the machine's C++ runtime is too old
    export LD_LIBRARY_PATH="$LD_LIBRARY_PATH:$PWD/$B/lib-fallback"
fi
if ! "$B/atmos" list >/dev/null 2>&1; then
    echo "gpu_check: the bundle does not run here:" >&2
    "$B/atmos" list 2>&1 | head -5 >&2
    exit 2
fi
export ATMOS_SOURCE_DIR="$PWD"
SIZE="${SIZE:-1920x1080}"
REPEAT="${REPEAT:-256}"
status=0
run() {  # run NAME COMMAND...: logs to $OUT/NAME.log, records the exit status
    local name="$1"
    shift
    echo "== $name: $*" | tee -a "$OUT/summary.txt"
    local t0=$SECONDS
    "$@" >"$OUT/$name.log" 2>&1
    local rc=$?
    echo "   rc=$rc, $((SECONDS - t0)) s" | tee -a "$OUT/summary.txt"
    tail -n 25 "$OUT/$name.log"
    [ $rc -eq 0 ] || status=1
}
device_tests='Cuda*:Backend*:Stages*:EmulatedDevice*'
models_arg=()
[ -n "${MODELS:-}" ] && models_arg=(--models "$MODELS")

phases=("$@")
[ ${#phases[@]} -eq 0 ] && phases=(info tests)
[ "${phases[*]}" = all ] && phases=(info tests sanitize bench paths)
for phase in "${phases[@]}"; do
    case "$phase" in
        info)
            run nvidia-smi nvidia-smi
            echo "bundle commit: $(cat $B/commit 2>/dev/null)" | tee -a "$OUT/summary.txt"
            run list "$B/atmos" list ;;
        tests)
            run tests "$B/atmos_tests" --gtest_filter="$device_tests" \
                --gtest_output="xml:$OUT/tests.xml" ;;
        sanitize)
            run memcheck compute-sanitizer --tool memcheck --error-exitcode 1 --leak-check full \
                "$B/atmos_tests" --gtest_filter="$device_tests"
            run racecheck compute-sanitizer --tool racecheck --error-exitcode 1 \
                "$B/atmos_tests" --gtest_filter="$device_tests" ;;
        bench)
            run bench "$B/atmos" bench --backend cuda --size "$SIZE" --repeat "$REPEAT" \
                --prepare-repeat 5 "${models_arg[@]}" -o "$OUT/bench_cuda.csv" ;;
        cpu-bench)
            run cpu-bench "$B/atmos" bench --backend cpu --size "$SIZE" --repeat 3 \
                "${models_arg[@]}" -o "$OUT/bench_cpu.csv" ;;
        paths)
            run paths "$B/atmos" bench --backend cuda --models reference --size "$SIZE" \
                --spp 64 --repeat 1 --warmup 1 -o "$OUT/bench_paths.csv" ;;
        roofline)
            metrics=dram__bytes_read.sum,dram__bytes_write.sum,gpu__time_duration.sum
            for op in fadd fmul ffma dadd dmul dfma; do
                metrics+=",smsp__sass_thread_inst_executed_op_${op}_pred_on.sum"
            done
            models="${MODELS:-$("$B/atmos" list | awk '/^models:/{m=1;next} /^[a-z]+:/{m=0} m && /^  [a-z]/{print $1}' | grep -v '^reference$')}"
            for m in ${models//,/ }; do
                run "ncu-$m" ncu --csv --page raw --print-units base --metrics "$metrics" \
                    --kernel-name regex:RenderKernel --launch-count 1 \
                    "$B/atmos" render --backend cuda --model "$m" --view "${VIEW:-ground-noon}" \
                    --size "$SIZE" --quiet -o "/tmp/ncu-$m.exr"
                cp "$OUT/ncu-$m.log" "$OUT/ncu_$m.csv"
            done
            run roofline python3 scripts/roofline.py "$OUT" --view "${VIEW:-ground-noon}" \
                --size "$SIZE" ;;
        noise)
            for view in ${NOISE_VIEWS:-ground-noon}; do
                for spp in ${NOISE_SPP:-1024 4096}; do
                    for seed in 1 2; do
                        run "ref-$view-$spp-$seed" "$B/atmos" render --backend cuda \
                            --model reference --view "$view" --size "$SIZE" --spp "$spp" \
                            --seed "$seed" --quiet -o "$OUT/ref-$view-$spp-$seed.exr"
                    done
                    run "noise-$view-$spp" "$B/atmos" flip --mode hdr \
                        "$OUT/ref-$view-$spp-1.exr" "$OUT/ref-$view-$spp-2.exr"
                    rm -f "$OUT"/ref-"$view"-"$spp"-*.exr "$OUT"/ref-"$view"-"$spp"-*variance*
                done
            done ;;
        *) echo "gpu_check: unknown phase '$phase'" >&2; exit 2 ;;
    esac
done
tar -czf /tmp/gpu_results.tar.gz -C "$OUT" . && mv /tmp/gpu_results.tar.gz "$OUT/"
exit $status
