#!/usr/bin/env python3
"""The path tracer's noise per second, RGB against spectral batch layouts (issue 17 item 2).

Runs `atmos sample` (sky queries) or `atmos render` (one view) twice with independent seeds for
each configuration and reports the noise of what a user sees, with the CPU seconds it took:

  sample: relative noise of the luminance Y (rms(Y1 - Y2) / sqrt(2) / mean Y), of one wavelength
          (or RGB green), and the chromaticity noise (rms distance of CIE xy between the two runs
          / sqrt(2));
  render: HDR-FLIP between the two renders (`atmos flip`), the noise as compare reports it.

RGB's luminance and chromaticity come from its three channels as linear sRGB (D65). The
spectral configurations: --batch-layout consecutive|interleaved x --batch-seeds same|distinct.
`equal-time ratio` = (noise / RGB noise) x sqrt(CPU / RGB CPU): the noise ratio at equal CPU
time for a Monte Carlo estimate (noise ~ 1/sqrt(time)).

Usage:
  scripts/spectral_noise.py [--atmos build/atmos] [--rgb-spp 4096] [--mode sample|render]
                            [--view ground-noon --size 80x45] [--wavelengths 360:830:40]
"""
import argparse
import csv
import io
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile

SRGB_TO_XYZ = ((0.4124, 0.3576, 0.1805), (0.2126, 0.7152, 0.0722), (0.0193, 0.1192, 0.9505))
CONFIGS = [("consecutive", "same"), ("consecutive", "distinct"), ("interleaved", "same"),
           ("interleaved", "distinct")]


def cpu_run(cmd, stdin_text=None):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, input=stdin_text, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode != 0:
        sys.exit(f"failed ({out.returncode}): {' '.join(cmd)}\n{out.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return out.stdout, cpu


def queries_csv():
    rows = ["altitude_m,mu,mu_s,azimuth_deg"]
    for mu_s in (0.5, 0.08):
        for i in range(10):
            for j in range(12):
                rows.append(f"0,{0.04 + 0.096 * i:.4f},{mu_s},{15 + 30 * j}")
    return "\n".join(rows) + "\n"


def xyz_rows(text, spectral):
    rows = list(csv.DictReader(io.StringIO(text)))
    out = []
    for r in rows:
        if spectral:
            out.append((float(r["X"]), float(r["Y"]), float(r["Z"])))
        else:
            rgb = (float(r["L_r"]), float(r["L_g"]), float(r["L_b"]))
            out.append(tuple(sum(m[k] * rgb[k] for k in range(3)) for m in SRGB_TO_XYZ))
    return rows, out


def sample_noise(a, b, rows_a, rows_b, column):
    n = len(a)
    mean_y = sum(v[1] for v in a + b) / (2 * n)
    dy = math.sqrt(sum((p[1] - q[1]) ** 2 for p, q in zip(a, b)) / n) / math.sqrt(2) / mean_y

    def xy(v):
        s = v[0] + v[1] + v[2]
        return (v[0] / s, v[1] / s)

    dc = math.sqrt(sum((xy(p)[0] - xy(q)[0]) ** 2 + (xy(p)[1] - xy(q)[1]) ** 2
                       for p, q in zip(a, b)) / n) / math.sqrt(2)
    if column not in rows_a[0]:  # the wavelength nearest 550 nm
        column = min((k for k in rows_a[0] if k.startswith("L_") and k[2:3].isdigit()),
                     key=lambda k: abs(float(k[2:]) - 550.0))
    va = [float(r[column]) for r in rows_a]
    vb = [float(r[column]) for r in rows_b]
    mean_l = sum(va + vb) / (2 * n)
    dl = math.sqrt(sum((p - q) ** 2 for p, q in zip(va, vb)) / n) / math.sqrt(2) / mean_l
    return dy, dc, dl


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--atmos", default="build/atmos")
    ap.add_argument("--atmosphere", default="earth-spectral")
    ap.add_argument("--model", default="reference")
    ap.add_argument("--mode", choices=("sample", "render"), default="sample")
    ap.add_argument("--view", default="ground-noon")
    ap.add_argument("--size", default="80x45")
    ap.add_argument("--rgb-spp", type=int, default=4096)
    ap.add_argument("--wavelengths", default="360:830:40")
    ap.add_argument("--column", default="",
                    help="sample mode: the single-wavelength column reported (default: the one "
                    "nearest 550 nm; RGB: L_g)")
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    count = int(args.wavelengths.split(":")[2]) if args.wavelengths.count(":") == 2 else len(
        args.wavelengths.split(","))
    batches = (count + 2) // 3
    spectral_spp = max(1, round(args.rgb_spp / batches))
    base = [args.atmos, args.mode, "-m", args.model, "-a", args.atmosphere, "-q",
            "--threads", str(args.threads)]
    tmp = tempfile.mkdtemp(prefix="spectral_noise_")
    results = []
    configs = [("rgb", None, None)] + [("spectral", lay, sd) for lay, sd in CONFIGS]
    for kind, layout, seeds in configs:
        spp = args.rgb_spp if kind == "rgb" else spectral_spp
        extra = [] if kind == "rgb" else ["--wavelengths", args.wavelengths, "--batch-layout",
                                          layout, "--batch-seeds", seeds]
        cpu_total = 0.0
        outs = []
        for seed in (1, 2):
            cmd = base + ["--spp", str(spp), "--seed", str(seed)] + extra
            if args.mode == "sample":
                text, cpu = cpu_run(cmd, queries_csv())
                outs.append(text)
            else:
                path = os.path.join(tmp, f"{kind}-{layout}-{seeds}-{seed}.exr")
                _, cpu = cpu_run(cmd + ["--view", args.view, "--size", args.size, "-o", path])
                outs.append(path)
            cpu_total += cpu
        cpu = cpu_total / 2
        name = "rgb" if kind == "rgb" else f"{layout}/{seeds}"
        if args.mode == "sample":
            rows_a, a = xyz_rows(outs[0], kind != "rgb")
            rows_b, b = xyz_rows(outs[1], kind != "rgb")
            column = "L_g" if kind == "rgb" else args.column
            dy, dc, dl = sample_noise(a, b, rows_a, rows_b, column)
            results.append((name, spp, cpu, dy, dc, dl))
        else:
            text, _ = cpu_run([args.atmos, "flip", outs[0], outs[1]])
            flip = float(text.split("mean FLIP:")[1].split()[0])
            results.append((name, spp, cpu, flip))
        print(f"{name}: spp {spp}, CPU {cpu:.2f} s", file=sys.stderr)
    shutil.rmtree(tmp, ignore_errors=True)
    rgb = results[0]
    if args.mode == "sample":
        print(f"# {len(queries_csv().splitlines()) - 1} queries, {args.atmosphere}, "
              f"{args.wavelengths} ({batches} batches), RGB {args.rgb_spp} spp")
        print("| configuration | spp | CPU s | Y noise | xy noise | one wavelength noise | "
              "equal-time ratio Y / xy / one |")
        print("|---|---|---|---|---|---|---|")
        for name, spp, cpu, dy, dc, dl in results:
            t = math.sqrt(cpu / rgb[2])
            print(f"| {name} | {spp} | {cpu:.2f} | {100 * dy:.3f} % | {dc:.2e} | {100 * dl:.3f} % "
                  f"| {dy / rgb[3] * t:.2f} / {dc / rgb[4] * t:.2f} / {dl / rgb[5] * t:.2f} |")
    else:
        print(f"# {args.view} {args.size}, {args.atmosphere}, {args.wavelengths} ({batches} "
              f"batches), RGB {args.rgb_spp} spp")
        print("| configuration | spp | CPU s | HDR-FLIP between seeds | equal-time ratio |")
        print("|---|---|---|---|---|")
        for name, spp, cpu, flip in results:
            t = math.sqrt(cpu / rgb[2])
            print(f"| {name} | {spp} | {cpu:.2f} | {flip:.4f} | {flip / rgb[3] * t:.2f} |")


if __name__ == "__main__":
    main()
