#!/usr/bin/env python3
"""The path tracer against DISORT's test problem 2 (Sweigart's Rayleigh slab; issue 32 item 3).

Emulates each case of data/benchmarks/disort_test2.csv with a thin homogeneous shell on a huge
planet (default: radius 1e9 m, thickness 1000 m; see docs/models/reference.md "Published
benchmarks"): Rayleigh scattering coefficient ssalb tau / H and an absorber of (1 - ssalb) tau / H
(the `absorption_extinction` term), both with constant density, no Mie, a black ground. Each
published intensity uu (per unit beam flux pi) becomes the radiance uu / pi per unit solar
irradiance, and is measured with `atmos sample` (a camera at the top, altitude H, looking down at
mu = -umu for light leaving the top; on the ground, altitude 0, looking up for light reaching the
ground; mu_s = umu0, azimuth = phi). The mean and its standard error come from --seeds independent
runs (seeds 1..K) of --spp paths each; z = (atmos - published) / standard error.

Prints one Markdown table row per case, direction and estimator, and the CPU seconds.

Usage:
  scripts/disort_benchmark.py [--atmos build/atmos] [--spp 4096] [--seeds 16]
      [--models reference,reference:estimator=tracking] [--cases 2A,2B,2C,2D]
      [--thickness 1000] [--radius 1e9] [--max-order 0] [--where all|top|ground]
      [--single-scattering]
"""
import argparse
import csv
import io
import json
import math
import os
import resource
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data", "benchmarks", "disort_test2.csv")


def read_cases(path):
    rows = [r for r in csv.DictReader(line for line in open(path) if not line.startswith("#"))]
    cases = {}
    for r in rows:
        cases.setdefault(r["case"], []).append(r)
    return cases


def atmosphere(tau, ssalb, thickness, radius):
    sigma = tau / thickness
    constant = {"layers": [{"constant_term": 1}]}
    return {
        "name": "disort-slab",
        "description": "a homogeneous Rayleigh slab with an absorber (scripts/disort_benchmark.py)",
        "bottom_radius": radius,
        "top_radius": radius + thickness,
        "rayleigh_scattering": ssalb * sigma,
        "rayleigh_density": constant,
        "mie_scattering": 0,
        "mie_extinction": 0,
        "mie_density": constant,
        "mie_phase_g": 0.8,
        "absorption_extinction": (1.0 - ssalb) * sigma,
        "absorption_density": constant,
        "ground_albedo": 0,
        "sun_angular_radius": 0.004675,
        "solar_irradiance": 1,
        "mu_s_min": -0.2,
    }


def query(row, thickness):
    umu = float(row["umu"])
    altitude = thickness if umu > 0 else 0.0
    return (altitude, -umu, float(row["umu0"]), float(row["phi_deg"]))


def single_scattering(row):
    """Order 1 of the plane-parallel slab (closed form, black ground, unit irradiance)."""
    tau, ssalb = float(row["tau"]), float(row["ssalb"])
    umu, mu0 = float(row["umu"]), float(row["umu0"])
    cos_theta = -mu0 * umu + math.sqrt((1 - mu0 * mu0) * (1 - umu * umu)) * math.cos(
        math.radians(float(row["phi_deg"])))
    phase = 3.0 / (16.0 * math.pi) * (1.0 + cos_theta * cos_theta)
    mu = abs(umu)
    if umu > 0:  # leaving the top
        return ssalb * phase * mu0 / (mu0 + mu) * (1.0 - math.exp(-tau * (1.0 / mu + 1.0 / mu0)))
    # reaching the ground
    return ssalb * phase * mu0 / (mu0 - mu) * (math.exp(-tau / mu0) - math.exp(-tau / mu))


def run(atmos, atm_path, model, spp, seed, queries_csv, max_order):
    spec = model if max_order == 0 else model + ":max-order=%d" % max_order
    cmd = [atmos, "sample", "-q", "--threads", "1", "-a", atm_path, "-m", spec, "--spp",
           str(spp), "--seed", str(seed)]
    out = subprocess.run(cmd, input=queries_csv, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit("atmos sample failed: " + out.stderr.strip())
    return [float(r["L_r"]) for r in csv.DictReader(io.StringIO(out.stdout))]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--atmos", default=os.path.join(HERE, "..", "build", "atmos"))
    p.add_argument("--data", default=DATA)
    p.add_argument("--spp", type=int, default=4096, help="paths per query per seed")
    p.add_argument("--seeds", type=int, default=16, help="independent runs (seeds 1..K)")
    p.add_argument("--models", default="reference,reference:estimator=tracking")
    p.add_argument("--cases", default="2A,2B,2C,2D")
    p.add_argument("--thickness", type=float, default=1000.0, help="the shell's thickness H (m)")
    p.add_argument("--radius", type=float, default=1e9, help="the planet's radius (m)")
    p.add_argument("--max-order", type=int, default=0, help="0: all orders")
    p.add_argument("--where", choices=("all", "top", "ground"), default="all",
                   help="only the light leaving the top, or only the light reaching the ground")
    p.add_argument("--single-scattering", action="store_true",
                   help="compare order 1 (max-order 1) with the plane-parallel closed form "
                   "instead of the published all-orders values (checks the emulation)")
    args = p.parse_args()
    if args.single_scattering:
        args.max_order = 1
    if args.seeds < 2:
        sys.exit("--seeds must be >= 2 (the standard error comes from the spread of the runs)")
    cases = read_cases(args.data)
    print("| case | tau | ssalb | where | umu | published uu/pi (or order 1) | model | atmos +- s.e. | "
          "rel. diff. | z |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.cases.split(","):
            rows = [r for r in cases[name] if args.where == "all" or
                    (float(r["umu"]) > 0) == (args.where == "top")]
            tau, ssalb = float(rows[0]["tau"]), float(rows[0]["ssalb"])
            atm_path = os.path.join(tmp, "slab_%s.json" % name)
            with open(atm_path, "w") as f:
                json.dump(atmosphere(tau, ssalb, args.thickness, args.radius), f)
            qs = [query(r, args.thickness) for r in rows]
            queries_csv = "altitude_m,mu,mu_s,azimuth_deg\n" + "".join(
                "%.17g,%.17g,%.17g,%.17g\n" % q for q in qs)
            for model in args.models.split(","):
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                runs = [run(args.atmos, atm_path, model, args.spp, s, queries_csv,
                            args.max_order) for s in range(1, args.seeds + 1)]
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
                k = len(runs)
                for i, r in enumerate(rows):
                    values = [run_values[i] for run_values in runs]
                    mean = sum(values) / k
                    var = sum((v - mean) ** 2 for v in values) / (k - 1)
                    se = math.sqrt(var / k)
                    want = (single_scattering(r) if args.single_scattering else
                            float(r["uu"]) / math.pi)
                    z = (mean - want) / se if se > 0 else float("nan")
                    worst = max(worst, abs(z)) if se > 0 else worst
                    where = "top, up" if float(r["umu"]) > 0 else "ground, down"
                    print("| %s | %g | %g | %s | %s | %.5e | `%s` | %.5e +- %.1e | %+.2f %% | %+.2f |"
                          % (name, tau, ssalb, where, r["umu"], want, model, mean, se,
                             100.0 * (mean / want - 1.0), z))
                print("<!-- %s %s: %d x %d paths per query, %.1f s CPU -->"
                      % (name, model, k, args.spp, cpu), flush=True)
    print("largest |z|: %.2f" % worst)


if __name__ == "__main__":
    main()
