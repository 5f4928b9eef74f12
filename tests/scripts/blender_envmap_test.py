"""Integration test (label `integration`, scripts/test.sh --integration): a real
renderer lit by atmos's environment map. Blender (Cycles, headless) renders a
white Lambertian plane under the equirect map plus the matching sun lamp
(examples/blender_envmap.py); its radiance must equal atmos's own horizontal
irradiance (direct + diffuse, `atmos irradiance`) / pi within 3 %.

Usage: blender_envmap_test.py --atmos PATH --blender PATH --example PATH --tmp DIR
"""

import argparse
import math
import os
import subprocess
import sys


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s\n%s" % (" ".join(cmd), r.stdout[-4000:], r.stderr[-4000:]))
    return r.stdout


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--atmos", required=True)
    p.add_argument("--blender", required=True)
    p.add_argument("--example", required=True)
    p.add_argument("--tmp", required=True)
    p.add_argument("--model", default="bruneton")
    p.add_argument("--elevation", type=float, default=30.0)
    p.add_argument("--azimuth", type=float, default=120.0)
    p.add_argument("--samples", type=int, default=64)
    a = p.parse_args()
    os.makedirs(a.tmp, exist_ok=True)
    sky = os.path.join(a.tmp, "blender_sky.exr")
    sun = "elevation=%g,azimuth=%g" % (a.elevation, a.azimuth)
    run([a.atmos, "render", "--model", a.model, "-q", "--camera", "projection=equirect",
         "--sun", sun, "--size", "1024x512", "-o", sky])
    rows = {}
    for line in run([a.atmos, "irradiance", "--model", a.model, "-q", "--sun", sun]).splitlines()[1:]:
        name, *values = line.split(",")
        rows[name] = [float(v) for v in values]
    direct, diffuse = rows["direct"], rows["diffuse"]
    out = run([a.blender, "-b", "--factory-startup", "-noaudio", "-P", a.example, "--",
               "--map", sky, "--elevation", str(a.elevation), "--azimuth", str(a.azimuth),
               "--direct", *[repr(v) for v in direct], "--samples", str(a.samples),
               "--out", os.path.join(a.tmp, "blender_plane.exr")])
    measured = None
    for line in out.splitlines():
        if line.startswith("RADIANCE "):
            measured = [float(v) for v in line.split()[1:4]]
    if measured is None:
        sys.exit("no RADIANCE line from Blender:\n" + out[-4000:])
    worst = 0.0
    for c, name in enumerate("rgb"):
        want = (direct[c] + diffuse[c]) / math.pi
        rel = measured[c] / want - 1.0
        worst = max(worst, abs(rel))
        print("%s: Blender %.6g, atmos (direct %.6g + diffuse %.6g) / pi = %.6g, %+.2f %%"
              % (name, measured[c], direct[c], diffuse[c], want, 100.0 * rel))
    print("largest difference %.2f %% (limit 3 %%)" % (100.0 * worst))
    if worst > 0.03:
        sys.exit(1)


main()
