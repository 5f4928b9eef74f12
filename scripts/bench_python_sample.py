#!/usr/bin/env python3
"""Times atmos.Model.sample on 10^6 queries, per query, on two threads: the
Python side of bench/sample_bench.cpp (BM_ModelSample*: the same queries
through Model::Sample in C++). Compare the two on the same machine:

    build/bench/atmos_bench --benchmark_filter=ModelSample
    PYTHONPATH=build/python python3 scripts/bench_python_sample.py
"""

import argparse
import time

import numpy as np

import atmos


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--models", nargs="*", default=["naive", "bruneton"])
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    atmos.set_threads(args.threads)
    i = np.arange(1000000)
    mu = -1.0 + 2.0 * (i % 1000) / 999.0
    mu_s = -0.2 + 1.2 * (i // 1000) / 999.0
    for name in args.models:
        m = atmos.Model(name).prepare("earth")
        m.sample(0.0, mu[:1000], mu_s[:1000], 0.0)  # warm up
        times = []
        for _ in range(args.repetitions):
            t0 = time.perf_counter()
            m.sample(0.0, mu, mu_s, 0.0)
            times.append(time.perf_counter() - t0)
        t = np.array(times) / i.size * 1e9
        print(f"{name}: m.sample on 10^6 queries, {args.threads} threads: "
              f"min {t.min():.1f} ns/query, median {np.median(t):.1f} ns/query "
              f"({args.repetitions} runs)")


if __name__ == "__main__":
    main()
