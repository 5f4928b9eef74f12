#!/usr/bin/env python3
"""Roofline table of atmos's render kernels from Nsight Compute counters.

Reads one ncu CSV per model (scripts/gpu_check.sh roofline writes them as
ncu_<model>.csv, `ncu --csv --page raw --print-units base`; the "details" page
layout with Metric Name / Metric Value columns is read too), and the kernel
medians of `atmos bench --backend cuda` (bench_cuda.csv) for the same view and
size. Per model: FP32 and FP64 FLOPs per pixel (add, mul: 1; fma: 2; the
special-function unit's exp / log / sin are not counted), DRAM bytes per pixel,
arithmetic intensity, and the rates at the bench's median time against the
device's peaks (--peak-fp32, --peak-fp64 in TFLOP/s, --peak-bw in TB/s;
defaults: H100 SXM, non-tensor).
Standard library only (it runs on the GPU machine's python3).
"""
import argparse
import csv
import glob
import os
import sys

FP32 = {"fadd": 1, "fmul": 1, "ffma": 2}
FP64 = {"dadd": 1, "dmul": 1, "dfma": 2}
PREFIX = "smsp__sass_thread_inst_executed_op_"
SUFFIX = "_pred_on.sum"


def number(text):
    text = (text or "").replace(",", "").strip()
    try:
        return float(text)
    except ValueError:
        return None


def read_ncu(path, kernel_pattern):
    """Sums each metric over the kernels whose name contains kernel_pattern."""
    with open(path, newline="") as f:
        lines = [l for l in f if l.startswith('"') or l.startswith("ID")]
    rows = list(csv.reader(lines))
    if not rows:
        return {}
    header = rows[0]
    sums = {}
    if "Metric Name" in header:  # details page: one row per (kernel, metric)
        k, n, v = (header.index(c) for c in ("Kernel Name", "Metric Name", "Metric Value"))
        for r in rows[1:]:
            if len(r) > v and kernel_pattern in r[k]:
                x = number(r[v])
                if x is not None:
                    sums[r[n]] = sums.get(r[n], 0.0) + x
        return sums
    k = header.index("Kernel Name")  # raw page: a units row, then one row per kernel
    for r in rows[1:]:
        if len(r) != len(header) or kernel_pattern not in r[k]:
            continue
        for name, text in zip(header, r):
            x = number(text)
            if x is not None and "__" in name:
                sums[name] = sums.get(name, 0.0) + x
    return sums


def bench_medians(path, view, size):
    out = {}
    if not os.path.exists(path):
        return out
    w, h = size.split("x")
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["view"] == view and r["width"] == w and r["height"] == h:
                out[r["model"]] = float(r["render_median_s"])
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folder", help="folder with ncu_<model>.csv and bench_cuda.csv")
    p.add_argument("--view", default="ground-noon")
    p.add_argument("--size", default="1920x1080")
    p.add_argument("--kernel", default="RenderKernel")
    p.add_argument("--peak-fp32", type=float, default=67.0)
    p.add_argument("--peak-fp64", type=float, default=34.0)
    p.add_argument("--peak-bw", type=float, default=3.35)
    a = p.parse_args()
    w, h = (int(x) for x in a.size.split("x"))
    pixels = w * h
    medians = bench_medians(os.path.join(a.folder, "bench_cuda.csv"), a.view, a.size)
    files = sorted(glob.glob(os.path.join(a.folder, "ncu_*.csv")))
    if not files:
        sys.exit("roofline: no ncu_*.csv in " + a.folder)
    cols = ["model", "fp32_flop_px", "fp64_flop_px", "dram_bytes_px", "flop_per_byte",
            "median_ms", "fp32_tflops", "fp64_tflops", "dram_tb_s", "fp32_%peak",
            "fp64_%peak", "dram_%peak"]
    print(",".join(cols))
    for path in files:
        model = os.path.basename(path)[4:-4]
        m = read_ncu(path, a.kernel)
        if not m:
            print(f"{model},no {a.kernel} counters in {path}")
            continue
        f32 = sum(m.get(PREFIX + op + SUFFIX, 0.0) * k for op, k in FP32.items())
        f64 = sum(m.get(PREFIX + op + SUFFIX, 0.0) * k for op, k in FP64.items())
        dram = m.get("dram__bytes_read.sum", 0.0) + m.get("dram__bytes_write.sum", 0.0)
        t = medians.get(model)
        row = [model, f32 / pixels, f64 / pixels, dram / pixels, (f32 + f64) / max(dram, 1.0)]
        if t:
            row += [t * 1e3, f32 / t / 1e12, f64 / t / 1e12, dram / t / 1e12,
                    100 * f32 / t / 1e12 / a.peak_fp32, 100 * f64 / t / 1e12 / a.peak_fp64,
                    100 * dram / t / 1e12 / a.peak_bw]
        print(",".join(x if isinstance(x, str) else f"{x:.4g}" for x in row))


if __name__ == "__main__":
    main()
