"""atmos.sun_position and `atmos sun` (issue 31 item 2): against an independent
ephemeris (PyEphem, Debian's python3-ephem), the CLI against Python, time zones,
broadcasting and bad input."""

import datetime as dt
import math
import random

import numpy as np
import pytest

import atmos


def _random_cases(n, seed):
    rng = random.Random(seed)
    start = dt.datetime(1950, 1, 1, tzinfo=dt.timezone.utc)
    span = (dt.datetime(2100, 12, 31, tzinfo=dt.timezone.utc) - start).total_seconds()
    cases = []
    for _ in range(n):
        t = start + dt.timedelta(seconds=rng.uniform(0.0, span))
        t = t.replace(microsecond=0)
        cases.append((t, rng.uniform(-89.9, 89.9), rng.uniform(-180.0, 180.0),
                      rng.uniform(0.0, 3000.0)))
    return cases


def _ephem_position(ephem, t, lat, lon, height):
    """PyEphem's topocentric sun without refraction (pressure 0), degrees."""
    obs = ephem.Observer()
    obs.lat = math.radians(lat)
    obs.lon = math.radians(lon)
    obs.elevation = height
    obs.pressure = 0.0  # alt is the geometric altitude only without refraction
    obs.date = ephem.Date(t.replace(tzinfo=None))  # UT
    sun = ephem.Sun(obs)
    return math.degrees(sun.alt), math.degrees(sun.az)


def _separation(e1, a1, e2, a2):
    e1, a1, e2, a2 = map(math.radians, (e1, a1, e2, a2))
    c = (math.sin(e1) * math.sin(e2) + math.cos(e1) * math.cos(e2) * math.cos(a1 - a2))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def compare_with_ephem(n=400, seed=2026):
    """Max |elevation|, |azimuth| (elevation within +-85 degrees) and angular
    differences in degrees between atmos and PyEphem at n random instants
    1950-2100, places and heights 0..3 km (one height per call: atmos takes a
    scalar height, so each case is its own call)."""
    ephem = pytest.importorskip("ephem")
    worst = {"elevation": 0.0, "azimuth": 0.0, "angle": 0.0}
    for t, lat, lon, h in _random_cases(n, seed):
        e, a = atmos.sun_position(t.strftime("%Y-%m-%dT%H:%M:%SZ"), lat, lon, height=h)
        e, a = float(e), float(a)
        ee, ea = _ephem_position(ephem, t, lat, lon, h)
        worst["elevation"] = max(worst["elevation"], abs(e - ee))
        if abs(ee) < 85.0:
            da = abs((a - ea + 180.0) % 360.0 - 180.0)
            worst["azimuth"] = max(worst["azimuth"], da)
        worst["angle"] = max(worst["angle"], _separation(e, a, ee, ea))
    return worst


def test_against_pyephem():
    worst = compare_with_ephem()
    print(f"\natmos vs PyEphem, 400 instants 1950-2100: max |d elevation| "
          f"{worst['elevation']:.6f} deg, max |d azimuth| {worst['azimuth']:.6f} deg, "
          f"max angle {worst['angle']:.6f} deg")
    assert worst["elevation"] <= 0.01
    assert worst["azimuth"] <= 0.01
    assert worst["angle"] <= 0.01


def test_worked_example_and_time_zone():
    # Reda & Andreas (2004) Appendix A.5, with refraction at 820 mbar, 11 C.
    e, a = atmos.sun_position("2003-10-17T12:30:30-07:00", 39.742476, -105.1786,
                              height=1830.14, pressure=820, temperature=11, delta_t=67)
    assert abs((90.0 - float(e)) - 50.11162) < 5e-6
    assert abs(float(a) - 194.34024) < 5e-6
    # The same instant in UTC, in India and as numpy datetime64 (UTC).
    times = ["2003-10-17T12:30:30-07:00", "2003-10-17T19:30:30Z", "2003-10-18T01:00:30+05:30"]
    e3, a3 = atmos.sun_position(times, 39.742476, -105.1786)
    e4, a4 = atmos.sun_position(np.array(["2003-10-17T19:30:30"], dtype="datetime64[s]"),
                                39.742476, -105.1786)
    assert np.all(e3 == e3[0]) and np.all(a3 == a3[0])
    assert e4[0] == e3[0] and a4[0] == a3[0]
    # An aware datetime.
    tz = dt.timezone(dt.timedelta(hours=-7))
    e5, _ = atmos.sun_position(dt.datetime(2003, 10, 17, 12, 30, 30, tzinfo=tz), 39.742476,
                               -105.1786)
    assert float(e5) == e3[0]


def test_broadcasting_and_batches():
    times = np.array(["2024-06-21T12:00:00Z", "2024-12-21T12:00:00Z"])
    lats = np.array([[0.0], [45.0], [-45.0]])
    e, a = atmos.sun_position(times, lats, 10.0)
    assert e.shape == (3, 2) and a.shape == (3, 2)
    for i in range(3):
        for j in range(2):
            e1, a1 = atmos.sun_position(times[j], float(lats[i, 0]), 10.0)
            assert float(e1) == e[i, j] and float(a1) == a[i, j]
    assert np.all(np.isfinite(e)) and np.all((a >= 0) & (a < 360))


def test_cli_matches_python(cli):
    rows = [("2024-06-21T12:00:00Z", 52.5, 13.4), ("2024-06-21T14:00:00+02:00", 52.5, 13.4),
            ("1969-07-20T20:17:40.5Z", 28.5, -80.6), ("2099-12-31T23:59:59-05:30", -33.9, 151.2)]
    text = "time,latitude,longitude\n" + "".join(f"{t},{la},{lo}\n" for t, la, lo in rows)
    code, out, err = cli("sun", stdin=text)
    assert code == 0, err
    lines = out.strip().split("\n")
    assert lines[0] == "time,latitude,longitude,elevation_deg,azimuth_deg"
    e, a = atmos.sun_position([r[0] for r in rows], [r[1] for r in rows], [r[2] for r in rows])
    for k, line in enumerate(lines[1:]):
        fields = line.split(",")
        assert fields[0] == rows[k][0]
        assert abs(float(fields[3]) - e[k]) <= 5e-7
        assert abs(float(fields[4]) - a[k]) <= 5e-7
    # The first two rows are the same instant.
    assert lines[1].split(",")[3:] == lines[2].split(",")[3:]
    # Refraction raises the sun (more near the horizon).
    code, out_r, err = cli("sun", "--pressure", "1013", "--temperature", "15", stdin=text)
    assert code == 0, err
    er, _ = atmos.sun_position([r[0] for r in rows], [r[1] for r in rows], [r[2] for r in rows],
                               pressure=1013, temperature=15)
    for k, line in enumerate(out_r.strip().split("\n")[1:]):
        assert abs(float(line.split(",")[3]) - er[k]) <= 5e-7
        if e[k] > -0.8:
            assert er[k] > e[k]


@pytest.mark.parametrize("stdin, expect", [
    ("time,latitude,longitude\n2024-06-21T12:00:00Z,95,0\n", "row 1: latitude 95 is outside -90..90"),
    ("time,latitude,longitude\n2024-06-21T12:00:00Z,0,0\n2024-06-21T12:00:00Z,0,-181\n",
     "row 2: longitude -181 is outside -180..180"),
    ("time,latitude,longitude\n2024-06-31T12:00:00Z,0,0\n", "row 1: time: '2024-06-31T12:00:00Z'"),
    ("time,latitude,longitude\n2024-06-21T12:00:00,0,0\n", "no UTC offset"),
    ("time,latitude,longitude\n2024-06-21T12:00:00Z,abc,0\n", "row 1: latitude 'abc' is not a number"),
    ("time,latitude,longitude\n2024-06-21T12:00:00Z,0\n", "row 1: expected 3 comma-separated"),
    ("time,lat,lon\n", "expected the header 'time,latitude,longitude'"),
    ("", "no input"),
])
def test_cli_bad_rows(cli, stdin, expect):
    code, out, err = cli("sun", stdin=stdin)
    assert code == 2
    assert out == ""
    assert err.startswith("atmos: error: ") and err.count("\n") == 1
    assert expect in err, err


def test_python_errors_name_the_argument():
    with pytest.raises(ValueError, match=r"latitudes\[1\]: latitude 91"):
        atmos.sun_position(["2024-06-21T12:00:00Z"] * 2, [0, 91], 0)
    with pytest.raises(ValueError, match=r"longitudes\[0\]: longitude -200"):
        atmos.sun_position("2024-06-21T12:00:00Z", 0, -200)
    with pytest.raises(ValueError, match=r"times\[1\]: .*month 13"):
        atmos.sun_position(["2024-06-21T12:00:00Z", "2024-13-01T00:00:00Z"], 0, 0)
    with pytest.raises(ValueError, match=r"times\[0\]: a datetime without a time zone"):
        atmos.sun_position(dt.datetime(2024, 1, 1), 0, 0)
    with pytest.raises(ValueError, match=r"times: contains NaT"):
        atmos.sun_position(np.array(["NaT"], dtype="datetime64[s]"), 0, 0)
    with pytest.raises(ValueError, match="do not broadcast"):
        atmos.sun_position(["2024-06-21T12:00:00Z"] * 2, [0, 1, 2], 0)
    with pytest.raises(ValueError, match="latitudes: expected numbers"):
        atmos.sun_position("2024-06-21T12:00:00Z", "north", 0)
    with pytest.raises(ValueError, match="pressure -5 is outside"):
        atmos.sun_position("2024-06-21T12:00:00Z", 0, 0, pressure=-5)
    with pytest.raises(ValueError, match=r"times\[0\]: expected an ISO-8601 string"):
        atmos.sun_position([12.5], 0, 0)
