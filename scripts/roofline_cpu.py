#!/usr/bin/env python3
"""CPU roofline of atmos's table models: the compute / bandwidth limit per query
against the measured time per query (issue 37 item 4).

1. Peaks of this machine, measured by a small C++ kernel compiled here with
   `g++ -O3 -march=native` into a temporary directory:
     * FLOP/s: independent chains of fused multiply-adds (2 FLOPs each) on
       GCC vector types of 16, 32 and 64 bytes and on scalars, float and double;
       the best vector width is the roofline's compute peak, the scalar double
       rate the peak of code that does not vectorise.
     * bytes/s: a streaming read (sum of floats, vector accumulators) of an array
       per thread at each --sizes (default: 1 MiB ~ L2, 64 MiB ~ L3, 1 GiB ~ DRAM).
   One thread and --threads threads (default: all); the best of --reps.
2. Per model: the per-query FLOPs and table bytes from a cost model derived by
   reading the lookup code (MODELS below; docs/performance.md, "Where the time
   goes", explains each count), for N channels (3 = RGB, 40 = a 40-wavelength
   wide batch), and the level of the memory hierarchy its tables live in.
   limit = max(FLOPs / FLOP peak, bytes / bandwidth of that level), one thread.
3. Measured time per query: `--costs CSV` (bench/query_cost.py's output: the
   model's ns_per_query minus the `empty` model's, i.e. the I/O removed), and
   any `--time MODEL:CHANNELS:NS[:LABEL]` given (e.g. the DISABLED_Cost test's
   figures); prints atmos / limit per row as a Markdown table.

Standard library only.

  bench/query_cost.py --atmos build/atmos --models empty,naive,bruneton,hillaire,\\
      atmosphere-plus --queries 20000 --reps 3 --no-callgrind --precompute '' -o qc.csv
  scripts/roofline_cpu.py --costs qc.csv --time bruneton:40:1526:wide
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

KERNEL = r"""
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

template <typename T, int B>
struct Vec {
    typedef T type __attribute__((vector_size(B)));
};

static double Now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// 12 independent FMA chains of V (a scalar or a GCC vector), in registers: the
// empty asm makes each value opaque (no folding of the loop) and costs nothing.
#define ATMOS_STEP(c)   \
    c = c * a + b;      \
    asm volatile("" : "+v"(c));
template <typename V>
static V FmaChains(long iters, V x, V a, V b) {
    V c0 = x, c1 = c0 + b, c2 = c1 + b, c3 = c2 + b, c4 = c3 + b, c5 = c4 + b;
    V c6 = c5 + b, c7 = c6 + b, c8 = c7 + b, c9 = c8 + b, c10 = c9 + b, c11 = c10 + b;
    for (long i = 0; i < iters; ++i) {
        ATMOS_STEP(c0) ATMOS_STEP(c1) ATMOS_STEP(c2) ATMOS_STEP(c3) ATMOS_STEP(c4)
        ATMOS_STEP(c5) ATMOS_STEP(c6) ATMOS_STEP(c7) ATMOS_STEP(c8) ATMOS_STEP(c9)
        ATMOS_STEP(c10) ATMOS_STEP(c11)
    }
    return ((c0 + c1) + (c2 + c3)) + ((c4 + c5) + (c6 + c7)) + ((c8 + c9) + (c10 + c11));
}
constexpr int kChains = 12;

// B bytes per vector (B == 0: scalars); returns the sum of the lanes.
template <typename T, int B>
static double FmaLoop(long iters) {
    if constexpr (B == 0) {
        return double(FmaChains<T>(iters, T(1), T(0.9999999), T(1e-7)));
    } else {
        typedef typename Vec<T, B>::type V;
        constexpr int W = B / sizeof(T);
        V x, a, b;
        for (int w = 0; w < W; ++w) {
            x[w] = T(1) + T(w) * T(1e-4);
            a[w] = T(0.9999999);
            b[w] = T(1e-7);
        }
        const V c = FmaChains<V>(iters, x, a, b);
        T s = 0;
        for (int w = 0; w < W; ++w) s += c[w];
        return double(s);
    }
}

static double Sink = 0;

template <typename T, int B>
static void Flops(const char* name, int threads, long iters, int reps) {
    const double per_iter = kChains * 2.0 * (B == 0 ? 1 : B / int(sizeof(T)));
    double best = 0;
    for (int r = 0; r < reps; ++r) {
        std::vector<double> sums(threads);
        const double t0 = Now();
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back([&, t] { sums[t] = FmaLoop<T, B>(iters); });
        for (auto& th : pool) th.join();
        const double dt = Now() - t0;
        for (double s : sums) Sink += s;
        const double rate = per_iter * iters * threads / dt;
        if (rate > best) best = rate;
    }
    std::printf("{\"kind\":\"flops\",\"what\":\"%s\",\"threads\":%d,\"per_s\":%.6g}\n", name,
                threads, best);
}

// A streaming read of `bytes` per thread, `passes` times; 8 vector accumulators.
static void Read(int threads, size_t bytes, int reps) {
    typedef float V __attribute__((vector_size(32)));
    const size_t n = bytes / sizeof(V);
    std::vector<V*> arrays(threads);
    for (int t = 0; t < threads; ++t) {
        arrays[t] = static_cast<V*>(std::aligned_alloc(64, n * sizeof(V)));
        std::memset(static_cast<void*>(arrays[t]), 0, n * sizeof(V));  // touch (per thread below)
    }
    const double target = 2.0e9;  // bytes read per thread per repetition, at least
    const int passes = int(target / double(bytes)) + 1;
    double best = 0;
    for (int r = 0; r < reps; ++r) {
        std::vector<double> sums(threads);
        const double t0 = Now();
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back([&, t] {
                const V* a = arrays[t];
                V s[8] = {};
                for (int p = 0; p < passes; ++p) {
                    for (size_t i = 0; i + 8 <= n; i += 8)
                        for (int k = 0; k < 8; ++k) s[k] += a[i + k];
                    asm volatile("" ::: "memory");
                }
                V tot = s[0] + s[1] + s[2] + s[3] + s[4] + s[5] + s[6] + s[7];
                sums[t] = tot[0];
            });
        for (auto& th : pool) th.join();
        const double dt = Now() - t0;
        for (double s : sums) Sink += s;
        const double rate = double(n) * sizeof(V) * passes * threads / dt;
        if (rate > best) best = rate;
    }
    for (V* a : arrays) std::free(a);
    std::printf("{\"kind\":\"read\",\"bytes\":%zu,\"threads\":%d,\"per_s\":%.6g}\n", bytes,
                threads, best);
}

// Dependent loads over a random cycle of 64-byte lines (Sattolo's shuffle) in
// an array of `bytes`: the latency of one cache-line miss at that level.
static void Chase(size_t bytes, int reps) {
    struct alignas(64) Line {
        size_t next;
    };
    const size_t n = bytes / sizeof(Line);
    std::vector<Line> a(n);
    for (size_t i = 0; i < n; ++i) a[i].next = i;
    unsigned long long x = 88172645463325252ull;
    for (size_t i = n - 1; i > 0; --i) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        const size_t j = x % i;
        const size_t t = a[i].next;
        a[i].next = a[j].next;
        a[j].next = t;
    }
    const long steps = 4000000;
    double best = 1e30;
    size_t p = 0;
    for (int r = 0; r < reps; ++r) {
        const double t0 = Now();
        for (long i = 0; i < steps; ++i) p = a[p].next;
        const double dt = (Now() - t0) / steps;
        if (dt < best) best = dt;
    }
    Sink += double(p);
    std::printf("{\"kind\":\"latency\",\"bytes\":%zu,\"threads\":1,\"seconds\":%.6g}\n",
                bytes, best);
}

int main(int argc, char** argv) {
    for (int i = 4; i < argc; ++i) Chase(std::strtoull(argv[i], nullptr, 10), std::atoi(argv[3]));
    const int threads = std::atoi(argv[1]);
    const long iters = std::atol(argv[2]);
    const int reps = std::atoi(argv[3]);
    for (int t : {1, threads}) {
        if (t == threads && threads == 1) break;
        Flops<double, 0>("double scalar", t, iters, reps);
        Flops<double, 16>("double 128-bit", t, iters / 2, reps);
        Flops<double, 32>("double 256-bit", t, iters / 4, reps);
        Flops<double, 64>("double 512-bit", t, iters / 8, reps);
        Flops<float, 0>("float scalar", t, iters, reps);
        Flops<float, 32>("float 256-bit", t, iters / 8, reps);
        Flops<float, 64>("float 512-bit", t, iters / 16, reps);
        for (int i = 4; i < argc; ++i) Read(t, std::strtoull(argv[i], nullptr, 10), reps);
    }
    std::fprintf(stderr, "sink %g\n", Sink);
    return 0;
}
"""

# ---- The per-query cost models (docs/performance.md, "Where the time goes").
# FLOPs: add, sub, mul, div, sqrt 1 each; a multiply-add 2; compares, min / max,
# floor, clamps 0; exp counted as EXP_FLOPS (a range reduction and a polynomial).
# A linear interpolation a (1 - f) + b f with (1 - f) shared by the channels:
# 3 FLOPs per channel. Bytes: table texels read (float32), and the 64-byte
# cache lines they span (lower bound: no pair of texels straddles a line).
EXP_FLOPS = 15


def lines(nbytes):
    return -(-nbytes // 64)


def bruneton(n):
    # SkyRadiance of a camera in the atmosphere (bruneton.h): geometry (r, mu,
    # mu_s, nu: lengths, dots, the top-of-atmosphere test) 30; the transmittance
    # (u, v) mapping 20 + 2 splits 4; ScatteringUvwz 36; Split4D 14; phase
    # functions 18 (Rayleigh 3, Cornette-Shanks 15). Per channel: two 4D
    # lookups (scattering, single Mie: 16 texels, 15 lerps each) 2 * 45,
    # the bilinear transmittance 9, the phase-weighted sum 3.
    flops = (30 + 24 + 36 + 14 + 18) + n * (2 * 45 + 9 + 3)
    # Texels: 2 tables x 16 (8 x-adjacent pairs: nu and nu + 1 are
    # scattering_mu_s = 32 texels apart) + the transmittance's 4 (2 pairs);
    # channels contiguous per texel (the wide tables too).
    useful = (2 * 16 + 4) * n * 4
    line_bytes = 64 * (2 * 8 * lines(2 * n * 4) + 2 * lines(2 * n * 4))
    return flops, useful, line_bytes


def atmosphere_plus(n):
    # AtmospherePlusEvaluator::Evaluate (atmosphere_plus.h): geometry 30;
    # per table, U(h) (a cube root, ~15) and V(h_row, mu) for 2 rows (~10 each)
    # -> 2 * 35, W(mu_s) 5; phases 18. Per channel (scattering has 4: RGB +
    # Mie, shared by the N colour channels as 1 extra): the 3D lookup's 7
    # lerps 21; the transmittance's 2 rows x (1 lerp + weighted add) 10; sum 3.
    flops = 30 + 2 * 35 + 5 + 18 + 21 + n * (21 + 10 + 3)
    # Scattering: 2 rows x 4 texels (y0, y1 x z0, z1), N + 1 channels, texels
    # of one row width * (N+1) * 4 bytes apart; transmittance 2 rows x 2 texels.
    useful = 8 * (n + 1) * 4 + 4 * n * 4
    line_bytes = 64 * (8 * lines((n + 1) * 4) + 4 * lines(n * 4))
    return flops, useful, line_bytes


def hillaire(n, steps=100):
    # The sample path (no per-frame tables): 4 sky-view texels, each a march of
    # `sky-view-steps` (default 100) steps (hillaire.h Integrate). Per step:
    # position, length, mu_s 21; densities 8 + 2 exp; sigma_r, sigma_m,
    # extinction 18; the ground test 5; two table mappings 26; the per-channel
    # work: bilinear transmittance + multiple scattering 2 * 9, S 7, exp(-sigma
    # dt) 1 exp + 1, the segment integral 4 + 2, T 1.
    per_step = 21 + 8 + 2 * EXP_FLOPS + 18 + 5 + 26 + n * (18 + 7 + EXP_FLOPS + 1 + 6 + 1)
    flops = 4 * (steps * per_step + 60) + 40
    # Two bilinear lookups of small tables (transmittance 256 x 64, multiple
    # scattering 32 x 32: L2-resident) per step.
    useful = 4 * steps * 2 * 4 * n * 4
    line_bytes = 4 * steps * 2 * 2 * 64 * lines(2 * n * 4)
    return flops, useful, line_bytes


def naive(n, steps=16, light_steps=8):
    # NaiveEvaluator (naive.h): per light sample position, radius, altitude 13,
    # densities 6 + 2 exp, weighted sums 6; per view step the light ray's setup
    # 15, its own densities 13 + 2 exp, and per channel the optical depth 4,
    # exp(-tau) 1 exp, the scattering term and sum 8. No tables.
    per_light = 13 + 6 + 2 * EXP_FLOPS + 6
    per_view = 15 + 13 + 2 * EXP_FLOPS + light_steps * per_light + n * (4 + EXP_FLOPS + 8)
    flops = steps * per_view + 60 + n * 6
    return flops, 0, 0


MODELS = {
    # name: (cost model, memory level its tables live in for random queries)
    "bruneton": (bruneton, "L3"),  # 2 x 12.6 MB 4D tables
    "atmosphere-plus": (atmosphere_plus, "L2"),  # 1 MB + 196 KB
    "hillaire": (hillaire, "L2"),  # 196 KB + 12 KB
    "naive": (naive, None),  # no tables
}
LEVEL_SIZE = {"L2": 1 << 20, "L3": 64 << 20, "DRAM": 1 << 30}


def measure_peaks(threads, sizes, reps, iters):
    cxx = os.environ.get("CXX", "g++")
    if not shutil.which(cxx):
        sys.exit("roofline_cpu.py: error: no C++ compiler (%s)" % cxx)
    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "peak.cpp")
        exe = os.path.join(tmp, "peak")
        with open(src, "w") as f:
            f.write(KERNEL)
        subprocess.run([cxx, "-std=c++17", "-O3", "-march=native", "-ffp-contract=fast", "-pthread", src, "-o", exe],
                       check=True)
        out = subprocess.run([exe, str(threads), str(iters), str(reps)] + [str(s) for s in sizes],
                             check=True, capture_output=True, text=True).stdout
    return [json.loads(l) for l in out.splitlines() if l.startswith("{")]


def read_costs(path, instructions):
    """ns per query minus `empty`'s; fills instructions[model] (lookup_instructions)."""
    ns = {}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if not {"kind", "model", "metric", "value"} <= set(reader.fieldnames or []):
            sys.exit("roofline_cpu.py: error: --costs %s is not bench/query_cost.py's CSV "
                     "(columns kind, model, metric, value)" % path)
        for r in reader:
            if r["kind"] == "query" and r["metric"] == "ns_per_query":
                ns[r["model"]] = float(r["value"])
            if r["kind"] == "query" and r["metric"] == "lookup_instructions":
                instructions[r["model"]] = float(r["value"])
    if "empty" not in ns:
        sys.exit("roofline_cpu.py: error: --costs %s has no `empty` row (the I/O to subtract)"
                 % path)
    return {m: v - ns["empty"] for m, v in ns.items() if m != "empty"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--costs", help="bench/query_cost.py CSV (ns_per_query, with `empty`)")
    ap.add_argument("--time", action="append", default=[],
                    help="MODEL:CHANNELS:NS[:LABEL], a measured time per query (repeatable)")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--sizes", default="1048576,67108864,1073741824",
                    help="read-bandwidth array bytes per thread (L2, L3, DRAM)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--iters", type=int, default=20000000, help="FMA loop iterations (scalar)")
    ap.add_argument("--peaks", help="read the peaks from this JSON (a --save-peaks file)")
    ap.add_argument("--save-peaks", help="write the measured peaks to this JSON")
    args = ap.parse_args()

    given = []
    for t in args.time:
        parts = t.split(":")
        if len(parts) < 3 or parts[0] not in MODELS:
            sys.exit("roofline_cpu.py: error: --time %r: want MODEL:CHANNELS:NS[:LABEL] with "
                     "MODEL in %s" % (t, ",".join(MODELS)))
        if int(parts[1]) < 1 or float(parts[2]) <= 0:
            sys.exit("roofline_cpu.py: error: --time %r: CHANNELS >= 1 and NS > 0" % t)
        given.append((parts[0], int(parts[1]), float(parts[2]),
                     parts[3] if len(parts) > 3 else "given"))

    sizes = [int(s) for s in args.sizes.split(",")]
    if args.peaks:
        with open(args.peaks) as f:
            peaks = json.load(f)
    else:
        peaks = measure_peaks(args.threads, sizes, args.reps, args.iters)
    if args.save_peaks:
        with open(args.save_peaks, "w") as f:
            json.dump(peaks, f, indent=1)

    print("## Peaks (best of %d)\n" % args.reps)
    print("| what | threads | rate |")
    print("|---|---|---|")
    for p in peaks:
        if p["kind"] == "latency":
            print("| dependent random line, %d MiB | 1 | %.1f ns |"
                  % (p["bytes"] >> 20, p["seconds"] * 1e9))
        elif p["kind"] == "flops":
            print("| FMA, %s | %d | %.1f GFLOP/s |" % (p["what"], p["threads"], p["per_s"] / 1e9))
        else:
            print("| read, %d MiB per thread | %d | %.1f GB/s |"
                  % (p["bytes"] >> 20, p["threads"], p["per_s"] / 1e9))

    one = [p for p in peaks if p["threads"] == 1]
    # The models compute their geometry in double, their lookups in float: the
    # double vector peak is the compute roof (float's is ~2x; compute is not the
    # binding roof of any table model either way).
    vec_peak = max(p["per_s"] for p in one if p.get("what", "").startswith("double "))
    scalar_peak = next(p["per_s"] for p in one if p.get("what") == "double scalar")
    bw = {}
    for level, size in LEVEL_SIZE.items():
        hits = [p for p in one if p["kind"] == "read" and p["bytes"] == size]
        if hits:
            bw[level] = hits[0]["per_s"]

    lat = {}
    for level, size in LEVEL_SIZE.items():
        hits = [p for p in one if p["kind"] == "latency" and p["bytes"] == size]
        if hits:
            lat[level] = hits[0]["seconds"]

    # The clock, from the 512-bit double FMA rate (2 FMA units x 8 lanes x 2 FLOPs).
    ghz = next((p["per_s"] for p in one if p.get("what") == "double 512-bit"), 0.0) / 32e9
    rows = []
    instructions = {}
    if args.costs:
        for m, ns in read_costs(args.costs, instructions).items():
            if m in MODELS:
                rows.append((m, 3, ns, "RGB, query_cost.py minus empty"))
    rows += given
    print("\n## Per query, one thread (double vector FMA peak %.1f GFLOP/s, scalar double %.1f;"
          " read %s)\n" % (vec_peak / 1e9, scalar_peak / 1e9,
                           ", ".join("%s %.1f GB/s" % (k, v / 1e9) for k, v in bw.items())))
    print("| model | channels | time | FLOPs | bytes (lines) | level | compute limit | "
          "memory limit | limit | atmos / limit | atmos / (FLOPs at scalar peak) | "
          "atmos / (lines x latency) | instructions (IPC) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for m, n, ns, label in rows:
        model, level = MODELS[m]
        flops, useful, line_bytes = model(n)
        t_flop = flops / vec_peak * 1e9
        t_mem = line_bytes / bw[level] * 1e9 if level and level in bw else 0.0
        limit = max(t_flop, t_mem)
        serial = line_bytes / 64 * lat[level] * 1e9 if level and level in lat else 0.0
        print("| %s (%s) | %d | %.0f ns | %d | %d (%d) | %s | %.1f ns | %.1f ns | %.1f ns | "
              "**%.0fx** | %.1fx | %s | %s |"
              % (m, label, n, ns, flops, useful, line_bytes, level or "-", t_flop, t_mem, limit,
                 ns / limit, ns / (flops / scalar_peak * 1e9),
                 "%.2fx" % (ns / serial) if serial else "-",
                 "%d (%.1f)" % (instructions[m], instructions[m] / (ns * ghz))
                 if m in instructions and label.startswith("RGB, query_cost") and ghz else "-"))
    print("\n(IPC at %.2f GHz, the clock the 512-bit FMA rate implies.)" % ghz)


if __name__ == "__main__":
    main()
