#!/usr/bin/env python3
"""atmos's FLIP table next to the thesis's Appendix A (issue 16 item 5).

    scripts/thesis_table.py OUT_DIR [OUT_DIR_THESIS_EXPOSURE]

OUT_DIR is an `atmos compare` output directory (flip.csv, reference_noise.csv) whose models
include the thesis's nine (preetham, empty, raymarched, schuler, naive, hillaire, neural,
flat, bruneton); OUT_DIR_THESIS_EXPOSURE optionally the same comparison with
`--exposure thesis`. Prints Markdown to stdout:

1. per view, atmos's FLIP of each model (and with the thesis's exposure rule) next to
   Appendix A (data/thesis/appendix_a_flip.csv);
2. per view, the pairwise order of the models: a pair the thesis orders one way "holds" when
   atmos orders it the same way, "flips" when atmos orders it the other way by more than the
   reference's noise in that view (reference_noise.csv: HDR-FLIP between its halves), and is
   "unresolved" when atmos's two values are within that noise;
3. the best model per view in each table (atmos's ties: every model within the noise of the
   lowest).

Only the standard library: runs anywhere Python 3 does.
"""
import csv
import os
import sys

MODELS = ["preetham", "empty", "raymarched", "schuler", "naive", "hillaire", "neural", "flat",
          "bruneton"]


def read_csv(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    header, body = rows[0], rows[1:]
    return {r[0]: dict(zip(header[1:], r[1:])) for r in body if r}


def read_noise(out_dir):
    rows = read_csv(os.path.join(out_dir, "reference_noise.csv"))
    noise = {}
    for view, cols in rows.items():
        # The noise column: "noise" or the first numeric column.
        value = cols.get("noise")
        if value is None:
            value = next(v for v in cols.values() if _is_number(v))
        noise[view] = float(value)
    return noise


def _is_number(text):
    try:
        float(text)
        return True
    except (TypeError, ValueError):
        return False


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    thesis = read_csv(os.path.join(root, "data", "thesis", "appendix_a_flip.csv"))
    ours = read_csv(os.path.join(argv[1], "flip.csv"))
    noise = read_noise(argv[1])
    ours_thesis_exposure = read_csv(os.path.join(argv[2], "flip.csv")) if len(argv) == 3 else None
    missing = [m for m in MODELS if m not in next(iter(ours.values()))]
    if missing:
        print(f"error: {argv[1]}/flip.csv lacks models {', '.join(missing)}", file=sys.stderr)
        return 2

    views = [v for v in thesis if v in ours]
    # Further columns of flip.csv (variants, e.g. bruneton with the thesis-era options): shown
    # in the first table, without a thesis value, and left out of the rankings.
    extra = [m for m in next(iter(ours.values())) if m not in MODELS and m != "best"]
    print("| view | reference noise | " + " | ".join(MODELS + extra) + " |")
    print("|---|---|" + "---|" * (len(MODELS) + len(extra)))
    for v in views:
        cells = []
        for m in MODELS:
            a = float(ours[v][m])
            t = float(thesis[v][m])
            cell = f"{a:.3f}"
            if ours_thesis_exposure is not None:
                cell += f" / {float(ours_thesis_exposure[v][m]):.3f}"
            cells.append(cell + f" ({t:.3f})")
        for m in extra:
            cell = f"{float(ours[v][m]):.3f}"
            if ours_thesis_exposure is not None:
                cell += f" / {float(ours_thesis_exposure[v][m]):.3f}"
            cells.append(cell)
        print(f"| {v} | {noise[v]:.3f} | " + " | ".join(cells) + " |")
    print()

    print("| view | pairs holding | flipped beyond the noise | unresolved (within the noise) |"
          " thesis best | atmos best (ties within the noise) | flips |")
    print("|---|---|---|---|---|---|---|")
    totals = [0, 0, 0]
    for v in views:
        held = flipped = unresolved = 0
        flips = []
        for i, a in enumerate(MODELS):
            for b in MODELS[i + 1:]:
                ta, tb = float(thesis[v][a]), float(thesis[v][b])
                oa, ob = float(ours[v][a]), float(ours[v][b])
                if ta == tb:
                    continue
                lo, hi = (a, b) if ta < tb else (b, a)
                olo, ohi = (oa, ob) if lo == a else (ob, oa)
                if abs(oa - ob) <= noise[v]:
                    unresolved += 1
                elif olo < ohi:
                    held += 1
                else:
                    flipped += 1
                    flips.append(f"{hi} < {lo} by {olo - ohi:.3f}")
        totals[0] += held
        totals[1] += flipped
        totals[2] += unresolved
        tbest = min(MODELS, key=lambda m: float(thesis[v][m]))
        lowest = min(float(ours[v][m]) for m in MODELS)
        obest = [m for m in MODELS if float(ours[v][m]) <= lowest + noise[v]]
        print(f"| {v} | {held} | {flipped} | {unresolved} | {tbest} | {' '.join(obest)} | "
              f"{'; '.join(flips) if flips else '-'} |")
    print(f"| all | {totals[0]} | {totals[1]} | {totals[2]} | | | |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
