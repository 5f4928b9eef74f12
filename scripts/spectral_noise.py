#!/usr/bin/env python3
"""The path tracer's noise per second: RGB, spectral batches and hero paths (issues 17, 37).

Runs `atmos sample` (sky queries) or `atmos render` (one view) twice with independent seeds for
each configuration and reports the noise of what a user sees, with the CPU seconds it took:

  sample: relative noise of the luminance Y (rms(Y1 - Y2) / sqrt(2) / mean Y), of one wavelength
          (or RGB green), and the chromaticity noise (rms distance of CIE xy between the two runs
          / sqrt(2));
  render: HDR-FLIP between the two renders (`atmos flip`), the noise as compare reports it.

RGB's luminance and chromaticity come from its three channels as linear sRGB (D65). The
spectral configurations: the model with spectral=batches (batches of three wavelengths per path)
and --batch-layout consecutive|interleaved x --batch-seeds same|distinct, and the model with
spectral=hero (hero-wavelength paths: every path carries all the wavelengths; issue 37 item 3),
at --hero-spp paths per pixel or query. `equal-time ratio` = (noise / RGB noise) x sqrt(CPU /
RGB CPU): the noise ratio at equal CPU time for a Monte Carlo estimate (noise ~ 1/sqrt(time));
`vs batches` the same against the default batches (interleaved/distinct). With --repeats K
each configuration runs K times (seed pairs 1-2, 3-4, ...) and the medians are reported.

Usage:
  scripts/spectral_noise.py [--atmos build/atmos] [--rgb-spp 4096] [--mode sample|render]
                            [--view ground-noon --size 80x45] [--wavelengths 360:830:40]
                            [--hero-spp 1024] [--repeats 3] [--configs rgb,hero,...]
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

    # Queries black in either run (a thick atmosphere at few paths) have no chromaticity.
    lit = [(p, q) for p, q in zip(a, b) if sum(p) > 0 and sum(q) > 0]
    dc = math.sqrt(sum((xy(p)[0] - xy(q)[0]) ** 2 + (xy(p)[1] - xy(q)[1]) ** 2
                       for p, q in lit) / max(len(lit), 1)) / math.sqrt(2)
    if column not in rows_a[0]:  # the wavelength nearest 550 nm
        column = min((k for k in rows_a[0] if k.startswith("L_") and k[2:3].isdigit()),
                     key=lambda k: abs(float(k[2:]) - 550.0))
    va = [float(r[column]) for r in rows_a]
    vb = [float(r[column]) for r in rows_b]
    mean_l = sum(va + vb) / (2 * n)
    dl = math.sqrt(sum((p - q) ** 2 for p, q in zip(va, vb)) / n) / math.sqrt(2) / mean_l
    return dy, dc, dl


def median(values):
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--atmos", default="build/atmos")
    ap.add_argument("--atmosphere", default="earth-spectral")
    ap.add_argument("--model", default="reference")
    ap.add_argument("--mode", choices=("sample", "render"), default="sample")
    ap.add_argument("--view", default="ground-noon")
    ap.add_argument("--size", default="80x45")
    ap.add_argument("--rgb-spp", type=int, default=4096)
    ap.add_argument("--hero-spp", type=int, default=0,
                    help="paths per pixel or query of the hero configuration (default: "
                    "--rgb-spp / 4)")
    ap.add_argument("--wavelengths", default="360:830:40")
    ap.add_argument("--column", default="",
                    help="sample mode: the single-wavelength column reported (default: the one "
                    "nearest 550 nm; RGB: L_g)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=1,
                    help="runs of each configuration (independent seed pairs); medians reported")
    ap.add_argument("--configs", default="",
                    help="comma-separated subset of rgb, hero, consecutive/same, "
                    "consecutive/distinct, interleaved/same, interleaved/distinct (default: all; "
                    "rgb is always run)")
    args = ap.parse_args()
    count = int(args.wavelengths.split(":")[2]) if args.wavelengths.count(":") == 2 else len(
        args.wavelengths.split(","))
    batches = (count + 2) // 3
    spectral_spp = max(1, round(args.rgb_spp / batches))
    hero_spp = args.hero_spp or max(1, args.rgb_spp // 4)
    base = [args.atmos, args.mode, "-a", args.atmosphere, "-q", "--threads", str(args.threads)]
    tmp = tempfile.mkdtemp(prefix="spectral_noise_")
    results = []
    configs = [("rgb", None, None), ("hero", None, None)] + [("spectral", lay, sd)
                                                            for lay, sd in CONFIGS]
    wanted = set(c for c in args.configs.split(",") if c)

    def name_of(kind, layout, seeds):
        return kind if kind in ("rgb", "hero") else f"{layout}/{seeds}"

    configs = [c for c in configs
               if not wanted or c[0] == "rgb" or name_of(*c) in wanted]
    for kind, layout, seeds in configs:
        name = name_of(kind, layout, seeds)
        spp = {"rgb": args.rgb_spp, "hero": hero_spp}.get(kind, spectral_spp)
        option = {"hero": "spectral=hero", "spectral": "spectral=batches"}.get(kind, "")
        model = args.model + ":" + option if option else args.model
        extra = [] if kind == "rgb" else ["--wavelengths", args.wavelengths]
        if kind == "spectral":
            extra += ["--batch-layout", layout, "--batch-seeds", seeds]
        runs = []
        for rep in range(args.repeats):
            cpu_total = 0.0
            outs = []
            for seed in (2 * rep + 1, 2 * rep + 2):
                cmd = base + ["-m", model, "--spp", str(spp), "--seed", str(seed)] + extra
                if args.mode == "sample":
                    text, cpu = cpu_run(cmd, queries_csv())
                    outs.append(text)
                else:
                    path = os.path.join(tmp, f"{name.replace('/', '-')}-{seed}.exr")
                    _, cpu = cpu_run(cmd + ["--view", args.view, "--size", args.size, "-o", path])
                    outs.append(path)
                cpu_total += cpu
            cpu = cpu_total / 2
            if args.mode == "sample":
                rows_a, a = xyz_rows(outs[0], kind != "rgb")
                rows_b, b = xyz_rows(outs[1], kind != "rgb")
                column = "L_g" if kind == "rgb" else args.column
                runs.append((cpu,) + sample_noise(a, b, rows_a, rows_b, column))
            else:
                text, _ = cpu_run([args.atmos, "flip", outs[0], outs[1]])
                runs.append((cpu, float(text.split("mean FLIP:")[1].split()[0])))
        med = tuple(median([r[k] for r in runs]) for k in range(len(runs[0])))
        results.append((name, spp) + med)
        print(f"{name}: spp {spp}, CPU {med[0]:.2f} s (median of {args.repeats})", file=sys.stderr)
    shutil.rmtree(tmp, ignore_errors=True)
    rgb = results[0]
    ref = next((r for r in results if r[0] == "interleaved/distinct"), None)
    if args.mode == "sample":
        print(f"# {len(queries_csv().splitlines()) - 1} queries, {args.atmosphere}, "
              f"{args.wavelengths} ({batches} batches), RGB {args.rgb_spp} spp, "
              f"medians of {args.repeats}")
        print("| configuration | spp | CPU s | Y noise | xy noise | one wavelength noise | "
              "equal-time ratio Y / xy / one | vs batches Y / xy / one |")
        print("|---|---|---|---|---|---|---|---|")
        for name, spp, cpu, dy, dc, dl in results:
            t = math.sqrt(cpu / rgb[2])
            vs = "-"
            if ref:
                u = math.sqrt(cpu / ref[2])
                vs = f"{dy / ref[3] * u:.2f} / {dc / ref[4] * u:.2f} / {dl / ref[5] * u:.2f}"
            print(f"| {name} | {spp} | {cpu:.2f} | {100 * dy:.3f} % | {dc:.2e} | {100 * dl:.3f} % "
                  f"| {dy / rgb[3] * t:.2f} / {dc / rgb[4] * t:.2f} / {dl / rgb[5] * t:.2f} "
                  f"| {vs} |")
    else:
        print(f"# {args.view} {args.size}, {args.atmosphere}, {args.wavelengths} ({batches} "
              f"batches), RGB {args.rgb_spp} spp, medians of {args.repeats}")
        print("| configuration | spp | CPU s | HDR-FLIP between seeds | equal-time ratio | "
              "vs batches |")
        print("|---|---|---|---|---|---|")
        for name, spp, cpu, flip in results:
            t = math.sqrt(cpu / rgb[2])
            vs = f"{flip / ref[3] * math.sqrt(cpu / ref[2]):.2f}" if ref else "-"
            print(f"| {name} | {spp} | {cpu:.2f} | {flip:.4f} | {flip / rgb[3] * t:.2f} | {vs} |")


if __name__ == "__main__":
    main()
