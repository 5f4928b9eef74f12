"""atmos.sun_position: the sun's elevation and azimuth for dates, times and
places (NREL SPA, as `atmos sun`; docs/sun.md)."""

from __future__ import annotations

import datetime as _dt

import numpy as _np

from . import _atmos


def _time_texts(times):
    """ISO-8601 texts (with an offset) and the shape of `times`."""
    if isinstance(times, (str, _dt.datetime, _np.datetime64)):
        arr = _np.empty((), dtype=object)
        arr[()] = times
    else:
        try:
            arr = _np.asarray(times)
        except Exception as e:  # noqa: BLE001 - any conversion failure is the argument's
            raise ValueError(f"times: cannot be read as an array ({e})") from None
    if arr.dtype.kind == "M":
        if _np.isnat(arr).any():
            raise ValueError("times: contains NaT (not a time)")
        # numpy datetime64 is UTC by convention; microseconds cover years 1..9999.
        texts = _np.datetime_as_string(arr.astype("datetime64[us]"), unit="us")
        return [t + "Z" for t in texts.reshape(-1).tolist()], arr.shape
    out = []
    for i, t in enumerate(arr.reshape(-1).tolist()):
        if isinstance(t, str):
            out.append(t)
        elif isinstance(t, _dt.datetime):
            if t.tzinfo is None or t.utcoffset() is None:
                raise ValueError(f"times[{i}]: a datetime without a time zone is ambiguous "
                                 "(give tzinfo, e.g. datetime.timezone.utc)")
            out.append(t.isoformat())
        elif isinstance(t, _np.datetime64):
            if _np.isnat(t):
                raise ValueError(f"times[{i}]: NaT (not a time)")
            out.append(str(_np.datetime_as_string(t.astype("datetime64[us]"), unit="us")) + "Z")
        else:
            raise ValueError(f"times[{i}]: expected an ISO-8601 string, a numpy datetime64 or an "
                             f"aware datetime, got {type(t).__name__}")
    return out, arr.shape


def _degrees(name, values):
    try:
        arr = _np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected numbers (degrees)") from None
    return arr


def _scalar(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    return v


def sun_position(times, latitudes, longitudes, *, height=0.0, pressure=None, temperature=None,
                 delta_t=None):
    """The sun's topocentric elevation and azimuth in degrees (azimuth clockwise
    from north) by NREL's SPA (Reda & Andreas 2004), as `atmos sun` computes it.

    times: ISO-8601 strings with Z or a UTC offset ("2024-06-21T12:00:00Z",
    "2024-06-21T14:00:00+02:00"), numpy datetime64 (UTC) or aware datetimes;
    latitudes (-90..90, north positive) and longitudes (-180..180, east
    positive) in degrees. The three broadcast against each other (numpy rules).
    height: observer height above sea level in m (parallax). The position is
    geometric (no refraction) unless `pressure` (mbar) or `temperature` (C) is
    given (the other then defaults to 1010 mbar / 10 C). delta_t: TT - UT in
    seconds (default: Espenak & Meeus's polynomial of the date).

    Returns (elevation, azimuth): float64 arrays of the broadcast shape (0-d
    arrays for scalar inputs). Bad input raises ValueError naming the argument."""
    texts, tshape = _time_texts(times)
    lat = _degrees("latitudes", latitudes)
    lon = _degrees("longitudes", longitudes)
    try:
        shape = _np.broadcast_shapes(tshape, lat.shape, lon.shape)
    except ValueError:
        raise ValueError(f"times, latitudes and longitudes: shapes {tshape}, {lat.shape} and "
                         f"{lon.shape} do not broadcast") from None
    index = _np.broadcast_to(_np.arange(len(texts)).reshape(tshape), shape).reshape(-1)
    flat_times = [texts[i] for i in index.tolist()]
    flat_lat = _np.broadcast_to(lat, shape).reshape(-1).tolist()
    flat_lon = _np.broadcast_to(lon, shape).reshape(-1).tolist()
    refraction = pressure is not None or temperature is not None
    p = 1010.0 if pressure is None else _scalar("pressure", pressure)
    t = 10.0 if temperature is None else _scalar("temperature", temperature)
    dt = float("nan") if delta_t is None else _scalar("delta_t", delta_t)
    if delta_t is not None and not _np.isfinite(dt):
        raise ValueError(f"delta_t: {delta_t!r} is not a finite number")
    e, a = _atmos.sun_position(flat_times, flat_lat, flat_lon, _scalar("height", height), p, t, dt,
                               refraction)
    return e.reshape(shape), a.reshape(shape)
