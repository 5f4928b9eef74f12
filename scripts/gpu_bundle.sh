#!/usr/bin/env bash
# Builds the CUDA binaries here and packs them, with the shared libraries the
# GPU machine lacks, into .gpu/ (git-ignored) for scripts/gpu_check.sh to run
# there. The GPU machines of this workplace have nvcc, CMake and ninja but no
# Debian -dev packages and no network, so atmos is built on this machine and
# carried (the device tool's `carry: [".gpu"]`, about 30 MB).
# Usage: scripts/gpu_bundle.sh [ARCHITECTURES]   (default 90: H100 / H200)
set -euo pipefail
cd "$(dirname "$0")/.."
arch="${1:-90}"
scripts/setup.sh build-gpu >/dev/null 2>&1 || true  # installs the packages
cmake -S . -B build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DATMOS_CUDA=ON \
      -DATMOS_CUDA_ARCHITECTURES="$arch" >/dev/null
cmake --build build-gpu -j "$(nproc)"
rm -rf .gpu && mkdir -p .gpu/lib .gpu/lib-fallback
cp build-gpu/atmos build-gpu/tests/atmos_tests build-gpu/bench/atmos_bench .gpu/
strip .gpu/atmos .gpu/atmos_tests .gpu/atmos_bench
# Every shared library but the C runtime's own (present on any Linux). The C++
# runtime goes to lib-fallback: gpu_check.sh uses it only if the machine's own
# is too old, so that tools like compute-sanitizer keep their newer one.
for bin in .gpu/atmos .gpu/atmos_tests .gpu/atmos_bench; do
    ldd "$bin" | awk '/=> \//{print $3}'
done | sort -u | grep -v -E '/(libc|libm|libpthread|libdl|librt|ld-linux[^/]*)\.so' |
    while read -r lib; do
        case "$(basename "$lib")" in
            libstdc++*|libgcc_s*) cp -L "$lib" .gpu/lib-fallback/ ;;
            *) cp -L "$lib" .gpu/lib/ ;;
        esac
    done
git describe --always --dirty --abbrev=40 > .gpu/commit
du -sh .gpu
echo "bundle for sm_$arch at $(cat .gpu/commit): .gpu/ (run scripts/gpu_check.sh on the GPU machine)"
