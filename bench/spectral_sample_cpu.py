#!/usr/bin/env python3
"""CPU time of `atmos sample` for one model: RGB, 40 wavelengths in batches of three, and wide
channel batches (docs/performance.md "Wide channel batches").

Usage: bench/spectral_sample_cpu.py ATMOS_BINARY MODEL [ROUNDS=3]

Each round runs the three configurations in turn (interleaved), each on 1 query (start-up and
precomputation) and on 2000 queries (altitude 0-20 km, mu in [-0.3, 1], mu_s in [-0.2, 1], as
bench/query_cost.py draws them; Python's random, seed 19), one thread, no table cache, and
takes the child's user + system time (getrusage). Prints the medians over the rounds: the
1-query time and the per-query time ((2000 queries - 1 query) / 1999), and their ratios to RGB.
"""
import os
import random
import resource
import statistics
import subprocess
import sys
import tempfile


def cpu_seconds(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def write_queries(path, count):
    rng = random.Random(19)
    with open(path, "w") as f:
        f.write("altitude_m,mu,mu_s,azimuth_deg\n")
        for _ in range(count):
            f.write(f"{20000 * rng.random():.3f},{-0.3 + 1.3 * rng.random():.6f},"
                    f"{-0.2 + 1.2 * rng.random():.6f},{360 * rng.random():.3f}\n")


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    binary, model = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    wl = ["--wavelengths", "380:780:40"]
    configs = {"rgb": [], "three": wl + ["--channel-batches", "three"],
               "wide": wl + ["--channel-batches", "wide"]}
    with tempfile.TemporaryDirectory() as tmp:
        one, many = os.path.join(tmp, "q1.csv"), os.path.join(tmp, "q2000.csv")
        write_queries(one, 1)
        write_queries(many, 2000)
        times = {k: {"one": [], "many": []} for k in configs}
        for r in range(rounds):
            for name, extra in configs.items():
                cmd = [binary, "sample", "--model", model, "--threads", "1", "-q", "--no-cache",
                       "-o", os.devnull, *extra, "-i"]
                times[name]["one"].append(cpu_seconds(cmd + [one]))
                times[name]["many"].append(cpu_seconds(cmd + [many]))
            print(f"round {r}:", {k: [round(v[-1], 3) for v in d.values()]
                                  for k, d in times.items()}, flush=True)
    med = {k: {m: statistics.median(v) for m, v in d.items()} for k, d in times.items()}
    rgb_one = med["rgb"]["one"]
    rgb_query = (med["rgb"]["many"] - rgb_one) / 1999
    for name in configs:
        m = med[name]
        query = (m["many"] - m["one"]) / 1999
        print(f"{name:6s} 1 query (start-up + prepare) {m['one']:.3f} s CPU "
              f"(x{m['one'] / rgb_one:.2f}), per query {query * 1e6:.1f} us "
              f"(x{query / rgb_query:.2f})")


if __name__ == "__main__":
    main()
