#!/usr/bin/env python3
"""An independent plane-parallel Monte Carlo of a conservative Henyey-Greenstein slab with the sun
at the zenith and a black ground (DISORT's test problem 3: g 0.75, tau 1 or 8; issue 32 item 4).

Written for atmos without its code: a slab in optical depth t (0 at the top), backward paths from
the camera (at the bottom looking up, or at the top looking down), exponential free paths, next-event
estimation to the zenith sun (transmittance exp(-t)), Henyey-Greenstein directions sampled exactly
(weight 1, single-scattering albedo 1). Prints the radiance per unit solar irradiance (DISORT's
uu / FBEAM) with its standard error for DISORT's six directions, to set beside atmos's path tracer
and DISORT's 32-moment answer (docs/models/reference.md "Published benchmarks").

Usage: scripts/hg_slab_mc.py [--tau 1] [--g 0.75] [--paths 2000000] [--runs 4]
"""
import argparse

import numpy as np


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tau", type=float, default=1.0)
    p.add_argument("--g", type=float, default=0.75)
    p.add_argument("--paths", type=int, default=2000000)
    p.add_argument("--runs", type=int, default=4)
    a = p.parse_args()
    g, tau = a.g, a.tau

    def hg(nu):
        return (1 - g * g) / (4 * np.pi * (1 + g * g - 2 * g * nu) ** 1.5)

    def sample_hg(xi):
        s = (1 - g * g) / (1 - g + 2 * g * xi)
        return np.clip((1 + g * g - s * s) / (2 * g), -1, 1)

    def run(n, start_t, dz0, seed):
        # dz: the cosine of the path's direction with the upward vertical (the camera's view).
        rng = np.random.default_rng(seed)
        t = np.full(n, start_t)
        dz = np.full(n, dz0)
        alive = np.ones(n, bool)
        radiance = np.zeros(n)
        for _ in range(100000):
            idx = np.nonzero(alive)[0]
            if idx.size == 0:
                break
            tn = t[idx] + np.log(rng.random(idx.size)) * dz[idx]  # up: t decreases
            out = (tn < 0) | (tn > tau)
            alive[idx[out]] = False
            idx, tn = idx[~out], tn[~out]
            t[idx] = tn
            # Next event to the sun at the zenith: scattering angle cosine nu = dz.
            radiance[idx] += hg(dz[idx]) * np.exp(-tn)
            c = sample_hg(rng.random(idx.size))
            phi = 2 * np.pi * rng.random(idx.size)
            d = dz[idx]
            dz[idx] = np.clip(d * c + np.sqrt(np.maximum(0, 1 - d * d)) *
                              np.sqrt(np.maximum(0, 1 - c * c)) * np.cos(phi), -1, 1)
        return radiance.mean(), radiance.var() / n

    print("umu,where,radiance,standard_error")
    for umu in (0.1, 0.5, 1.0, -1.0, -0.5, -0.1):
        # DISORT's umu is the light's direction; the camera looks against it.
        start, dz0 = (0.0, -umu) if umu > 0 else (tau, -umu)
        runs = [run(a.paths, start, dz0, 1000 * i + int(10 * umu) + 17) for i in range(a.runs)]
        mean = np.mean([r[0] for r in runs])
        se = np.sqrt(np.sum([r[1] for r in runs])) / a.runs
        print(f"{umu:+.1f},{'top' if umu > 0 else 'bottom'},{mean:.6e},{se:.1e}")


if __name__ == "__main__":
    main()
