#!/usr/bin/env python3
"""Zenith sky radiance against sun elevation: a model next to the path tracer.

Plots L(zenith) per unit solar irradiance at the ground, R, G and B, for the
sun from 10 degrees below the horizon to the zenith, from one model (a line)
and from the Monte Carlo reference (points with 2-sigma bars from independent
seeds). Uses the atmos Python module (docs/python.md) and Matplotlib (Agg).

A query's answer does not depend on the batch it is asked in (issue 33), so
the model's curve is what it answers for each elevation alone: hillaire, for
one, reads each query's own sky-view texels, as its renders do (until issue 33
a batch of many sun elevations fell back to a 40-step ray march, whose red at
the zenith sun was 12 % below the path tracer: a bias of the fallback, not of
the model).

    PYTHONPATH=build/python python3 examples/zenith_vs_sun.py \\
        --model bruneton --spp 2048 -o docs/images/python_zenith_vs_sun.png
"""

import argparse
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import atmos  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="bruneton", help="NAME[:OPTION=VALUE...]")
    ap.add_argument("--atmosphere", default="earth")
    ap.add_argument("--spp", type=int, default=2048, help="reference paths per query and seed")
    ap.add_argument("--seeds", type=int, default=4, help="independent reference estimates")
    ap.add_argument("--points", type=int, default=23, help="reference sun elevations")
    ap.add_argument("-o", "--output", default="zenith_vs_sun.png")
    args = ap.parse_args()

    atm = atmos.Atmosphere.load(args.atmosphere)
    model = atmos.Model(args.model).prepare(atm)
    reference = atmos.Model("reference").prepare(atm)

    # The model: a dense curve, one call (NumPy arrays broadcast).
    elev = np.linspace(-10.0, 90.0, 401)
    t0 = time.perf_counter()
    L_model, _ = model.sample(0.0, 1.0, np.sin(np.radians(elev)), 0.0)
    t_model = time.perf_counter() - t0

    # The path tracer: fewer elevations, several seeds for the error bars.
    elev_ref = np.linspace(-10.0, 90.0, args.points)
    mu_s = np.sin(np.radians(elev_ref))
    t0 = time.perf_counter()
    runs = np.stack([reference.sample(0.0, 1.0, mu_s, 0.0, spp=args.spp, seed=s)[0]
                     for s in range(args.seeds)])
    t_ref = time.perf_counter() - t0
    L_ref = runs.mean(axis=0)
    err = 2.0 * runs.std(axis=0, ddof=1) / np.sqrt(args.seeds) if args.seeds > 1 else None

    fig, (ax, axr) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1.3]})
    colours = ("tab:red", "tab:green", "tab:blue")
    for c, (name, col) in enumerate(zip("RGB", colours)):
        ax.plot(elev, L_model[:, c], color=col, lw=1.6, label=f"{model.spec} {name}")
        ax.errorbar(elev_ref, L_ref[:, c], yerr=None if err is None else err[:, c], fmt="o",
                    ms=3.5, color=col, mfc="white", capsize=2,
                    label=f"reference {name} ({args.spp} x {args.seeds} paths)")
        # Relative difference at the reference's elevations.
        at = np.interp(elev_ref, elev, L_model[:, c])
        ok = L_ref[:, c] > 1e-6
        axr.plot(elev_ref[ok], (at[ok] - L_ref[ok, c]) / L_ref[ok, c] * 100.0, "o-", ms=3,
                 color=col, lw=1)
    ax.set_yscale("log")
    ax.set_ylabel("zenith radiance / solar irradiance  [1/sr]")
    ax.set_title(f"Zenith sky at the ground, atmosphere {args.atmosphere}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    axr.axhline(0.0, color="k", lw=0.8)
    axr.set_xlabel("sun elevation [deg]")
    axr.set_ylabel("model - ref [%]")
    axr.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    print(f"model {model.spec}: {elev.size} queries in {t_model:.3f} s; reference: "
          f"{elev_ref.size * args.seeds} queries x {args.spp} paths in {t_ref:.1f} s; "
          f"wrote {args.output}")


if __name__ == "__main__":
    main()
