#!/usr/bin/env python3
"""The float16 accuracy of a bake's tables (docs/engine.md, "RGBA tables and KTX2"):
per table, the largest relative error of tables.f16 against tables.f32 over the
values in binary16's normal range (|v| >= 2^-14), the largest absolute error below
it, and how many values are that small. Usage: float16_accuracy.py BAKE_DIR..."""
import json
import pathlib
import sys

import numpy as np


def report(directory):
    d = pathlib.Path(directory)
    bake = json.loads(next(p for p in d.glob("*.json") if p.name != "tables_rgba.json").read_text())
    raw = bake["raw"]
    f32 = np.fromfile(d / raw["float32"]["file"], dtype="<f4")
    f16 = np.fromfile(d / raw["float16"]["file"], dtype="<f2")
    for name, t in sorted(raw["tables"].items()):
        a = f32[t["float32_offset"] // 4:][:t["values"]].astype(np.float64)
        b = f16[t["float16_offset"] // 2:][:t["values"]].astype(np.float64)
        normal = np.abs(a) >= 2.0 ** -14
        rel = np.max(np.abs(b[normal] - a[normal]) / np.abs(a[normal])) if normal.any() else 0.0
        small = ~normal
        ab = np.max(np.abs(b[small] - a[small])) if small.any() else 0.0
        print(f"{d.name} {name}: max relative error {rel:.3e} (|v| >= 2^-14), "
              f"max absolute error {ab:.3e} below it ({small.mean() * 100:.2f} % of values), "
              f"max |v| {np.max(np.abs(a)):.4g}")


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        report(arg)
