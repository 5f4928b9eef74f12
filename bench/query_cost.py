#!/usr/bin/env python3
"""Per-query cost of atmos's models through `atmos sample`, and the
precomputation's CPU seconds per stage, into one CSV (issue 19 item 5).

Per model (table models are baked once and loaded with --load, so the
precomputation is not counted in the per-query figures):
  * ns_per_query: CPU time (user + sys of the child, one thread) of a run with
    2N queries minus a run with N queries, divided by N: start-up, loading
    and the query-independent work cancel. Median of --reps interleaved runs
    (every model's pair of runs, then the next repetition).
  * instructions_per_query: the same difference of callgrind's instruction
    counts (valgrind --tool=callgrind), when valgrind is installed: exact and
    insensitive to the machine's load. `lookup_instructions` subtracts the
    `empty` model's count (the I/O: parse and print).
Per table model (--precompute): `atmos bench --threads 1` of one 16x16 view,
each precomputation stage's median wall time (one thread: CPU time) and the
whole Prepare()'s CPU seconds (getrusage of `atmos bake`, all threads).

Rows: build,kind,model,metric,value,unit,detail. Standard library only.

  bench/query_cost.py --atmos build/atmos --output bench_query_cost.csv
"""
import argparse
import csv
import os
import random
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile

DEFAULT_MODELS = "empty,preetham,oneil,naive,bruneton,hillaire,atmosphere-plus"
TABLE_MODELS = {"bruneton", "hillaire", "atmosphere-plus"}


def write_queries(path, n, seed):
    rng = random.Random(seed)
    with open(path, "w") as f:
        f.write("altitude_m,mu,mu_s,azimuth_deg\n")
        for _ in range(n):
            f.write("%.17g,%.17g,%.17g,%.17g\n" % (rng.uniform(0.0, 20e3), rng.uniform(-0.3, 1.0),
                                                   rng.uniform(-0.2, 1.0), rng.uniform(0, 180)))


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def child_cpu(cmd, stdin_path):
    """Runs cmd with stdin from a file; returns the child's user + sys seconds."""
    before = children_cpu()
    with open(stdin_path, "rb") as f:
        subprocess.run(cmd, stdin=f, stdout=subprocess.DEVNULL, check=True)
    return children_cpu() - before


def callgrind_instructions(cmd, stdin_path, tmp):
    out = os.path.join(tmp, "callgrind.out")
    with open(stdin_path, "rb") as f:
        subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out] + cmd,
                       stdin=f, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    with open(out) as f:
        for line in f:
            if line.startswith("summary:") or line.startswith("totals:"):
                return int(line.split()[1])
    raise RuntimeError("no totals in callgrind output")


def sample_cmd(atmos, model, load_dir):
    cmd = [atmos, "sample", "--model", model, "--threads", "1"]
    if load_dir:
        cmd += ["--load", load_dir]
    return cmd


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--atmos", default="build/atmos",
                    help="the CLI; several, comma-separated, are measured interleaved "
                    "(e.g. a baseline build and this one)")
    ap.add_argument("--models", default=DEFAULT_MODELS)
    ap.add_argument("--queries", type=int, default=20000, help="N (runs of N and 2N queries)")
    ap.add_argument("--callgrind-queries", type=int, default=300)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--no-callgrind", action="store_true")
    ap.add_argument("--precompute", default="bruneton",
                    help="comma-separated table models whose precomputation is timed ('' none)")
    ap.add_argument("--output", "-o", default="bench_query_cost.csv")
    a = ap.parse_args()
    builds = [b for b in a.atmos.split(",") if b]
    models = [m for m in a.models.split(",") if m]
    use_callgrind = not a.no_callgrind and shutil.which("valgrind") is not None
    rows = []
    tmp = tempfile.mkdtemp(prefix="atmos_query_cost_")
    try:
        q1, q2 = os.path.join(tmp, "q1.csv"), os.path.join(tmp, "q2.csv")
        write_queries(q1, a.queries, 1)
        write_queries(q2, 2 * a.queries, 1)  # the first N rows are q1's
        c1, c2 = os.path.join(tmp, "c1.csv"), os.path.join(tmp, "c2.csv")
        write_queries(c1, a.callgrind_queries, 2)
        write_queries(c2, 2 * a.callgrind_queries, 2)
        loads = {}
        prepare_cpu = {}
        for b in builds:
            for m in models:
                if m in TABLE_MODELS:
                    d = os.path.join(tmp, "bake_%d_%s" % (builds.index(b), m))
                    before = children_cpu()
                    subprocess.run([b, "bake", "--model", m, "-o", d], check=True,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                    prepare_cpu[(b, m)] = children_cpu() - before
                    loads[(b, m)] = d
        times = {(b, m): [] for b in builds for m in models}
        for _ in range(a.reps):
            for m in models:
                for b in builds:
                    cmd = sample_cmd(b, m, loads.get((b, m)))
                    t1 = child_cpu(cmd, q1)
                    t2 = child_cpu(cmd, q2)
                    times[(b, m)].append((t2 - t1) / a.queries * 1e9)
        instr = {}
        if use_callgrind:
            for b in builds:
                for m in models:
                    cmd = sample_cmd(b, m, loads.get((b, m)))
                    i1 = callgrind_instructions(cmd, c1, tmp)
                    i2 = callgrind_instructions(cmd, c2, tmp)
                    instr[(b, m)] = (i2 - i1) / a.callgrind_queries
        for b in builds:
            for m in models:
                rows.append((b, "query", m, "ns_per_query",
                             "%.1f" % statistics.median(times[(b, m)]), "ns",
                             "median of %d; CPU time, 1 thread, %d vs %d queries" %
                             (a.reps, a.queries, 2 * a.queries)))
                if (b, m) in instr:
                    rows.append((b, "query", m, "instructions_per_query",
                                 "%.0f" % instr[(b, m)], "instr", "callgrind, %d vs %d queries" %
                                 (a.callgrind_queries, 2 * a.callgrind_queries)))
                    if (b, "empty") in instr and m != "empty":
                        rows.append((b, "query", m, "lookup_instructions",
                                     "%.0f" % (instr[(b, m)] - instr[(b, "empty")]), "instr",
                                     "minus the empty model's I/O"))
            for m in [x for x in a.precompute.split(",") if x]:
                if (b, m) in prepare_cpu:
                    rows.append((b, "precompute", m, "prepare_cpu_s",
                                 "%.2f" % prepare_cpu[(b, m)], "s",
                                 "atmos bake, all threads, CPU time"))
                out = os.path.join(tmp, "bench.csv")
                stages = os.path.join(tmp, "bench_stages.csv")
                subprocess.run([b, "bench", "--models", m, "--views", "ground-noon", "--size",
                                "16x16", "--repeat", "1", "--threads", "1", "-o", out,
                                "--stages-output", stages], check=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                with open(stages, newline="") as f:
                    for r in csv.DictReader(f):
                        if r["view"] != "prepare":
                            continue
                        rows.append((b, "stage", m, r["stage"],
                                     "%.3f" % (float(r["kernel_median_ms"]) / 1e3), "s",
                                     "one thread, %s items" % r["items"]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    with open(a.output, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["build", "kind", "model", "metric", "value", "unit", "detail"])
        w.writerows(rows)
    for r in rows:
        print(",".join(str(x) for x in r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
