#!/usr/bin/env python3
"""Cross-check of atmos's FLIP against an independent float64 implementation.

Written in pure Python from /work/shared/specs/flip.md, deliberately the other
way round from src/atmos/metrics/flip.cpp: unseparated 2-D kernels (as the
PyTorch version of FLIP), double precision, per-pixel loops. Renders a small
test pair with `atmos render`, runs `atmos flip --mode ldr|hdr -o map.pfm`,
and prints both means and the largest per-pixel difference of the maps.
Usage: scripts/check_flip.py [build/atmos]   (about a minute: pure Python)
"""
import math
import os
import struct
import subprocess
import sys
import tempfile

ATMOS = sys.argv[1] if len(sys.argv) > 1 else "build/atmos"

# ---- spec 2.1 colour transforms (float64) ---------------------------------------------------
WN = (0.950428545, 1.0, 1.088900371)


def rgb2xyz(c):
    r, g, b = c
    return ((10135552 * r + 8788810 * g + 4435075 * b) / 24577794,
            (2613072 * r + 8788810 * g + 887015 * b) / 12288897,
            (1425312 * r + 8788810 * g + 70074185 * b) / 73733382)


def xyz2rgb(c):
    x, y, z = c
    return (3.241003275 * x - 1.537398934 * y - 0.498615861 * z,
            -0.969224334 * x + 1.875930071 * y + 0.041554224 * z,
            0.055639423 * x - 0.204011202 * y + 1.057148933 * z)


def xyz2ycxcz(c):
    x, y, z = c[0] / WN[0], c[1] / WN[1], c[2] / WN[2]
    return (116 * y - 16, 500 * (x - y), 200 * (y - z))


def ycxcz2xyz(c):
    y = (c[0] + 16) / 116
    x = y + c[1] / 500
    z = y - c[2] / 200
    return (x * WN[0], y * WN[1], z * WN[2])


def xyz2lab(c):
    d = 6 / 29

    def f(t):
        return t ** (1 / 3) if t > d ** 3 else t / (3 * d * d) + 4 / 29
    fx, fy, fz = f(c[0] / WN[0]), f(c[1] / WN[1]), f(c[2] / WN[2])
    return (116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz))


def clamp01(c):
    return tuple(min(max(v, 0.0), 1.0) for v in c)


def hunt(lab):
    return (lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2])


def hyab(a, b):
    return abs(a[0] - b[0]) + math.hypot(a[1] - b[1], a[2] - b[2])


def conv2d(plane, w, h, kernel, r):
    """Correlation with a (2r+1)^2 kernel, clamp-to-edge."""
    out = [0.0] * (w * h)
    n = 2 * r + 1
    for y in range(h):
        for x in range(w):
            s = 0.0
            for j in range(n):
                yy = min(max(y + j - r, 0), h - 1) * w
                krow = kernel[j * n:(j + 1) * n]
                for i in range(n):
                    s += krow[i] * plane[yy + min(max(x + i - r, 0), w - 1)]
            out[y * w + x] = s
    return out


def ldr_flip(ref, test, w, h, ppd):
    pi = math.pi
    # Spec 2.2 step 2: the 2-D CSF kernels, each normalized to sum 1.
    r = math.ceil(3 * math.sqrt(0.04 / (2 * pi * pi)) * ppd)
    consts = [(1, 0.0047, 0, 1e-5), (1, 0.0053, 0, 1e-5), (34.1, 0.04, 13.5, 0.025)]
    csf = []
    for a1, b1, a2, b2 in consts:
        k = []
        for j in range(-r, r + 1):
            for i in range(-r, r + 1):
                r2 = (i / ppd) ** 2 + (j / ppd) ** 2
                k.append(a1 * math.sqrt(pi / b1) * math.exp(-pi * pi * r2 / b1) +
                         a2 * math.sqrt(pi / b2) * math.exp(-pi * pi * r2 / b2))
        s = sum(k)
        csf.append([v / s for v in k])
    # Spec 2.3: 2-D feature kernels normalized directly.
    sigma = 0.5 * 0.082 * ppd
    R = math.ceil(3 * sigma)
    g = {i: math.exp(-i * i / (2 * sigma * sigma)) for i in range(-R, R + 1)}

    def kern2d(fn):
        k = [fn(i, j) for j in range(-R, R + 1) for i in range(-R, R + 1)]
        pos = sum(v for v in k if v > 0)
        neg = -sum(v for v in k if v < 0)
        return [v / pos if v > 0 else (v / neg if v < 0 else 0.0) for v in k]
    ex = kern2d(lambda i, j: -i * g[i] * g[j])
    ey = kern2d(lambda i, j: -j * g[i] * g[j])
    px = kern2d(lambda i, j: (i * i / sigma ** 2 - 1) * g[i] * g[j])
    py = kern2d(lambda i, j: (j * j / sigma ** 2 - 1) * g[i] * g[j])

    def prepare(img):
        ycc = [xyz2ycxcz(rgb2xyz(clamp01(c))) for c in img]
        planes = [[c[k] for c in ycc] for k in range(3)]
        filt = [conv2d(planes[k], w, h, csf[k], r) for k in range(3)]
        yn = [(v + 16) / 116 for v in planes[0]]
        e = [math.hypot(a, b) for a, b in zip(conv2d(yn, w, h, ex, R), conv2d(yn, w, h, ey, R))]
        p = [math.hypot(a, b) for a, b in zip(conv2d(yn, w, h, px, R), conv2d(yn, w, h, py, R))]
        lab = []
        for i in range(w * h):
            rgb = clamp01(xyz2rgb(ycxcz2xyz((filt[0][i], filt[1][i], filt[2][i]))))
            lab.append(hunt(xyz2lab(rgb2xyz(rgb))))
        return lab, e, p
    lr, er, pr = prepare(ref)
    lt, et, pt = prepare(test)
    cmax = hyab(hunt(xyz2lab(rgb2xyz((0, 1, 0)))), hunt(xyz2lab(rgb2xyz((0, 0, 1))))) ** 0.7
    pccmax = 0.4 * cmax
    out = []
    for i in range(w * h):
        e = hyab(lr[i], lt[i]) ** 0.7
        dec = e * 0.95 / pccmax if e < pccmax else 0.95 + (e - pccmax) / (cmax - pccmax) * 0.05
        def_ = (max(abs(er[i] - et[i]), abs(pr[i] - pt[i])) / math.sqrt(2)) ** 0.5
        out.append(dec ** (1 - def_))
    return out


def hdr_flip(ref, test, w, h, ppd):
    k = (0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14)  # ACES
    a, b, c = k[0] - 0.85 * k[3], k[1] - 0.85 * k[4], k[2] - 0.85 * k[5]
    d1 = -b / (2 * a)
    xt = d1 + math.sqrt(d1 * d1 - c / a)
    lum = sorted(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] for p in ref)
    start = math.log2(xt / lum[-1])
    stop = math.log2(xt / lum[len(lum) // 2])
    n = max(2, math.ceil(stop - start))
    step = (stop - start) / (n - 1)
    tm = lambda x: (k[0] * x * x + k[1] * x + k[2]) / (k[3] * x * x + k[4] * x + k[5])
    best = [0.0] * (w * h)
    for e in range(n):
        s = 2 ** (start + e * step)
        ri = [clamp01(tuple(tm(v * s) for v in p)) for p in ref]
        ti = [clamp01(tuple(tm(v * s) for v in p)) for p in test]
        m = ldr_flip(ri, ti, w, h, ppd)
        best = [max(x, y) for x, y in zip(best, m)]
    return best, (start, stop, n)


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        fmt = "<" if scale < 0 else ">"
        data = f.read()
    ch = 3 if kind == b"PF" else 1
    vals = struct.unpack(fmt + "f" * (w * h * ch), data)
    rows = [vals[y * w * ch:(y + 1) * w * ch] for y in range(h)][::-1]  # bottom-up
    return [tuple(row[x * ch:(x + 1) * ch]) for row in rows for x in range(w)], w, h


def main():
    tmp = tempfile.mkdtemp()
    ref_pfm, test_pfm = os.path.join(tmp, "ref.pfm"), os.path.join(tmp, "test.pfm")
    size = "40x24"
    subprocess.run([ATMOS, "render", "--model", "naive:steps=64", "--view", "ground-sunrise",
                    "--size", size, "-q", "-o", ref_pfm], check=True)
    subprocess.run([ATMOS, "render", "--model", "naive:steps=4:light-steps=2", "--view",
                    "ground-sunrise", "--size", size, "-q", "-o", test_pfm], check=True)
    ppd = 67.0206451
    for mode in ("ldr", "hdr"):
        map_pfm = os.path.join(tmp, "map.pfm")
        out = subprocess.run([ATMOS, "flip", ref_pfm, test_pfm, "--mode", mode, "-o", map_pfm],
                             check=True, capture_output=True, text=True).stdout
        ours_mean = float(out.split()[-1])
        ref_img, w, h = read_pfm(ref_pfm)
        test_img, _, _ = read_pfm(test_pfm)
        if mode == "ldr":
            theirs = ldr_flip(ref_img, test_img, w, h, ppd)
            info = ""
        else:
            theirs, rng = hdr_flip(ref_img, test_img, w, h, ppd)
            info = " exposures %.6f..%.6f (%d)" % rng
        mean = sum(theirs) / len(theirs)
        line = "%s: atmos mean %.6f, independent float64 mean %.6f, |diff| %.2e%s" % (
            mode.upper(), ours_mean, mean, abs(ours_mean - mean), info)
        ours, _, _ = read_pfm(map_pfm)
        worst = max(abs(a[0] - b) for a, b in zip(ours, theirs))
        line += ", max per-pixel |diff| %.2e" % worst
        print(line)


if __name__ == "__main__":
    main()
