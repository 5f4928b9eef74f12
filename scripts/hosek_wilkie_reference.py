#!/usr/bin/env python3
"""Independent check values for the `hosek-wilkie` model (tests/hosek_wilkie_test.cpp).

Evaluates Hosek & Wilkie 2012 (ACM TOG 31(4)) eq. 8-9 straight from the published coefficient
JSON (data/hosek-wilkie-2012/), with no atmos code: the quintic Bezier over
x = (elevation / (pi/2))^(1/3), the linear blend in turbidity and albedo, then
F(theta, gamma) = (1 + A exp(B / (cos theta + 0.01))) (C + D exp(E gamma) + F cos^2 gamma
                   + G chi(H, gamma) + I sqrt(cos theta)),
chi(g, a) = (1 + cos^2 a) / (1 + g^2 - 2 g cos a)^(3/2), and L = F * L_M.
The data store each configuration's nine values in the order A B C D E F G I H (H, the
anisotropy g of chi, last). Prints the authors' radiance for a few cases, in the data's units.
Usage: scripts/hosek_wilkie_reference.py [DATA_DIR]"""
import json, math, os, sys

here = os.path.dirname(os.path.abspath(__file__))
data_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, '..', 'data', 'hosek-wilkie-2012')


def load(name):
    with open(os.path.join(data_dir, name + '.json')) as f:
        return json.load(f)


def bernstein5(x):
    return [math.comb(5, k) * (1 - x) ** (5 - k) * x ** k for k in range(6)]


def cooked(d, ch, turbidity, albedo, elevation):
    """The ten values (A B C D E F G I H, L_M) at this turbidity, albedo, solar elevation."""
    x = (elevation / (math.pi / 2)) ** (1 / 3)
    b = bernstein5(x)
    t_lo = min(int(math.floor(turbidity)), 9)
    u = turbidity - t_lo
    out = [0.0] * 10
    for a, wa in ((0, 1 - albedo), (1, albedo)):
        for t, wt in ((t_lo, 1 - u), (t_lo + 1, u)):
            for k in range(6):
                w = wa * wt * b[k]
                base = ((a * 10 + (t - 1)) * 6 + k)
                for p in range(9):
                    out[p] += w * d['config'][ch][base * 9 + p]
                out[9] += w * d['radiance'][ch][base]
    return out


def radiance(c, theta, gamma):
    A, B, C, D, E, F, G, I, H = c[:9]
    chi = (1 + math.cos(gamma) ** 2) / (1 + H * H - 2 * H * math.cos(gamma)) ** 1.5
    f = (1 + A * math.exp(B / (math.cos(theta) + 0.01))) * (
        C + D * math.exp(E * gamma) + F * math.cos(gamma) ** 2 + G * chi + I * math.sqrt(math.cos(theta)))
    return f * c[9]


def spectral(d, nm, turbidity, albedo, elevation, theta, gamma):
    x = (nm - 320.0) / 40.0
    i = min(int(math.floor(x)), 9)
    u = x - i
    lo = radiance(cooked(d, i, turbidity, albedo, elevation), theta, gamma)
    hi = radiance(cooked(d, i + 1, turbidity, albedo, elevation), theta, gamma)
    return (1 - u) * lo + u * hi


# (turbidity, albedo, sun elevation deg, view zenith deg, gamma deg)
CASES = [(3.0, 0.1, 30.0, 60.0, 40.0), (2.5, 0.0, 5.0, 80.0, 10.0), (7.3, 0.65, 70.0, 60.0, 75.0),
         (10.0, 1.0, 90.0, 45.0, 45.0), (1.0, 0.3, 0.0, 89.0, 120.0)]

# The extraterrestrial solar radiance of the authors' path tracer at 320..720 nm (reference
# implementation 1.4a, originalSolarRadianceTable) and the sun's solid angle (clear-sky-models).
SOLAR = [7500.0, 12500.0, 21127.5, 26760.5, 30663.7, 27825.0, 25503.8, 25134.2, 23212.1, 21526.7,
         19870.8]
SUN_SOLID_ANGLE = 6.87e-5


def solar_irradiance(nm):
    x = (nm - 320.0) / 40.0
    i = min(int(math.floor(x)), 9)
    u = x - i
    return ((1 - u) * SOLAR[i] + u * SOLAR[i + 1]) * SUN_SOLID_ANGLE


def sun_y():
    """Y (W m^-2) of that irradiance: sum over the CIE 1931 rows 360..720 nm of E ybar 5 nm."""
    path = os.path.join(here, '..', 'data', 'spectra', 'cie1931-2deg.csv')
    total = 0.0
    with open(path) as f:
        for line in f:
            if line.startswith('#') or line.startswith('nm'):
                continue
            nm, _, ybar, _ = (float(v) for v in line.split(','))
            if nm <= 720.0:
                total += solar_irradiance(nm) * ybar * 5.0
    return total


if __name__ == '__main__':
    rgb, xyz, spe = load('rgb'), load('xyz'), load('spectral')
    print('# kHosekWilkieSunY = %.10g W/m^2' % sun_y())
    print('# layout check: rgb config[0] (R), albedo 1, turbidity 4, control point 2, parameter index 7:',
          rgb['config'][0][((1 * 10 + 3) * 6 + 2) * 9 + 7])
    print('# layout check: spectral radiance[5] (520 nm), albedo 0, turbidity 10, control point 5:',
          spe['radiance'][5][(0 * 10 + 9) * 6 + 5])
    for T, a, el, th, g in CASES:
        e, t, gm = math.radians(el), math.radians(th), math.radians(g)
        r = [radiance(cooked(rgb, c, T, a, e), t, gm) for c in range(3)]
        z = [radiance(cooked(xyz, c, T, a, e), t, gm) for c in range(3)]
        s = [spectral(spe, nm, T, a, e, t, gm) for nm in (320.0, 550.0, 700.0)]
        print('{T=%g, albedo=%g, elev=%g, theta=%g, gamma=%g}' % (T, a, el, th, g))
        print('  rgb %.10g %.10g %.10g' % tuple(r))
        print('  xyz %.10g %.10g %.10g' % tuple(z))
        print('  spectral 320 550 700 nm %.10g %.10g %.10g' % tuple(s))
