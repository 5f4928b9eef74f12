#!/usr/bin/env bash
# Installs the Debian packages atmos builds with (only those missing), then
# configures and builds. Usage: scripts/setup.sh [--sanitize] [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."

sanitize=OFF
build_dir=""
for arg in "$@"; do
    case "$arg" in
        --sanitize) sanitize=ON ;;
        *) build_dir="$arg" ;;
    esac
done
if [ -z "$build_dir" ]; then
    if [ "$sanitize" = ON ]; then build_dir=build-asan; else build_dir=build; fi
fi

# chromium + a font: the report test loads out/index.html in headless Chromium.
# (The viewer test also renders `atmos viewer`'s page there: WebGL2 on SwiftShader.)
# python3-*, pybind11-dev: the Python module (import atmos, python/) and its
# pytest suite, built for Debian's /usr/bin/python3; matplotlib: examples/.
# libegl-dev .. libgl1-mesa-dri: the OpenGL 3.3 host examples/gl_host, headless
# through EGL (Mesa's llvmpipe runs it on the CPU in its test, GlHost.*).
packages=(cmake g++ make ninja-build pkg-config libopenexr-dev libpng-dev nlohmann-json3-dev
          libcli11-dev libnlopt-dev libtbb-dev libgtest-dev libgmock-dev libbenchmark-dev clang-format
          chromium fonts-dejavu-core
          python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
          python3-ephem glslang-tools spirv-cross spirv-tools libopenmpi-dev openmpi-bin
          libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "atmos setup: installing ${missing[*]}" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

werror=OFF
if [ -n "${CI:-}" ]; then werror=ON; fi
build_type=Release
cuda=AUTO
extra=()
if [ "$sanitize" = ON ]; then
    # -O1 -g1: 45 % less compile time than RelWithDebInfo's -O2 -g under ASan+UBSan
    # (hillaire.cpp: 82 vs 149 CPU s), with line numbers in the reports; no
    # CUDA and no micro-benchmarks in the sanitizer build.
    build_type=RelWithDebInfo; cuda=OFF
    # No MPI either: Open MPI's own allocations would read as leaks to ASan.
    extra=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DATMOS_BUILD_BENCH=OFF
        -DATMOS_MPI=OFF)
fi
# Instruction set (CMakeLists.txt, ATMOS_ARCH): x86-64-v3 (AVX2, FMA) when this
# machine runs it (glibc's loader lists the levels the CPU supports), else the
# compiler's baseline. The binaries then need such a CPU: ATMOS_ARCH= (empty)
# in the environment builds for any x86-64.
arch="${ATMOS_ARCH-auto}"
if [ "$arch" = auto ]; then
    arch=""
    if [ "$sanitize" = OFF ] && /lib64/ld-linux-x86-64.so.2 --help 2>/dev/null |
            grep -q "x86-64-v3 (supported"; then
        arch=x86-64-v3
    fi
fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" -DATMOS_ARCH="$arch" \
      -DATMOS_WERROR="$werror" -DATMOS_SANITIZE="$sanitize" -DATMOS_CUDA="$cuda" "${extra[@]}" >/dev/null
cmake --build "$build_dir" -j "$(nproc)"
