"""atmos: sky models, the Monte Carlo reference path tracer and image metrics.

The same library as the `atmos` command line (docs/python.md):

    import atmos
    atm = atmos.Atmosphere.load("earth")
    m = atmos.Model("bruneton", orders=4)
    m.prepare(atm)
    L, T = m.sample(altitude=0.0, mu=np.linspace(0, 1, 50), mu_s=0.5, azimuth=0.0)
    img = m.render(view="ground-noon", size=(480, 270))   # float32 H x W x 3

Errors of the library (unknown names, options out of range, invalid
atmosphere fields, NaN queries) are ValueError with the command line's message.
Output values a model got NaN, infinite or negative are written as 0 and
counted, as by the command line: Model.sample and Model.render then warn
(RuntimeWarning), or raise ValueError with strict=True (the CLI's --strict).
"""

from __future__ import annotations

import collections
import json as _json
import os as _os
import warnings as _warnings

import numpy as _np

from . import _atmos

__all__ = [
    "Atmosphere", "Model", "FlipResult", "RmseResult", "models", "model_info", "views",
    "view_names", "atmosphere_presets", "flip", "rmse", "bake", "read_image", "write_image",
    "set_threads", "thread_count",
]


def models():
    """The registered model names, in the registry's order (as `atmos list`)."""
    return _atmos.models()


def model_info(name):
    """A model's description: name, title, citation, summary, capabilities and
    its option table as a list of dicts (name, type, default, range, min, max,
    choices, unit, help, shapes_tables). ValueError for an unknown name."""
    return _atmos.model_info(name)


def atmosphere_presets():
    """Names of the shipped atmosphere presets (data/atmospheres)."""
    return _atmos.atmosphere_presets()


def view_names():
    """The names of the 12 standard views (docs/views.md)."""
    return _atmos.view_names()


def views(atmosphere="earth"):
    """The standard views for an atmosphere as dicts (name, description,
    position, forward, right, up, vfov_deg, sun_direction, sun_irradiance,
    exposure); camera altitudes are measured from its bottom radius."""
    return _atmos.view_info(Atmosphere.load(atmosphere)._json)


def read_image(path):
    """Reads an EXR, NPY, PFM or PNG image as linear float32 H x W x 3."""
    return _atmos.read_image(_os.fspath(path))


def write_image(image, path, exposure=1.0):
    """Writes an H x W x 3 (or H x W) array; the format follows the extension
    (.exr .png .npy .pfm); `exposure` applies to PNG only."""
    _atmos.write_image(image, _os.fspath(path), float(exposure))


def set_threads(threads):
    """Limits the worker threads of every later call (0: all cores)."""
    _atmos.set_threads(int(threads))


def thread_count():
    """The number of worker threads calls use now."""
    return _atmos.thread_count()


# Fields the JSON text leaves out at their default (the second Mie lobe,
# written only when it has a weight): read as attributes, settable by replace().
_OPTIONAL_FIELDS = {"mie_phase_g2": 0.0, "mie_phase_weight2": 0.0}


class Atmosphere:
    """A validated atmosphere (SI units, the fields of data/atmospheres/*.json).

    Fields read as attributes (`atm.mie_phase_g`, `atm.rayleigh_scattering`,
    `atm.mie_density["layers"][1]["exp_scale"]`); `atm.replace(FIELD=VALUE,
    ...)` returns a changed copy, validated; assigning an attribute does the
    same in place. Invalid values raise ValueError naming the field."""

    __slots__ = ("_json", "_fields")

    def __init__(self, _json_text):
        object.__setattr__(self, "_json", _json_text)
        object.__setattr__(self, "_fields", _json.loads(_json_text))

    @classmethod
    def load(cls, source="earth", overrides=()):
        """A preset name ("earth", ...), a JSON file path, a dict of every
        field (the preset format), or an Atmosphere. `overrides`: strings
        FIELD=VALUE as `--set` takes them (presets and files only)."""
        if isinstance(source, Atmosphere):
            if overrides:
                raise ValueError("overrides apply to a preset name or a file only")
            return source
        if isinstance(source, dict):
            if overrides:
                raise ValueError("overrides apply to a preset name or a file only")
            for k, v in source.items():
                _check_finite(k, v)
            return cls(_atmos.atmosphere_from_json(
                _json.dumps({k: _plain(v) for k, v in source.items()}), "<dict>"))
        if isinstance(source, (str, _os.PathLike)):
            return cls(_atmos.load_atmosphere(_os.fspath(source), list(overrides)))
        raise TypeError("Atmosphere.load: expected a preset name, a path, a dict or an "
                        f"Atmosphere, got {type(source).__name__}")

    def to_dict(self):
        """Every field as a dict (a deep copy), the preset format."""
        return _json.loads(self._json)

    def to_json(self):
        """The JSON text of the preset format."""
        return self._json

    def fields(self):
        return list(self._fields)

    def replace(self, **fields):
        """A copy with the given fields replaced (validated; ValueError naming
        the field)."""
        d = self.to_dict()
        for k, v in fields.items():
            if k not in d and k not in _OPTIONAL_FIELDS:
                raise ValueError(f"unknown atmosphere field '{k}' (fields: {', '.join(d)})")
            _check_finite(k, v)
            d[k] = _plain(v)
        return Atmosphere(_atmos.atmosphere_from_json(_json.dumps(d), "<replace>"))

    def __getattr__(self, name):
        fields = object.__getattribute__(self, "_fields")
        if name not in fields and name in _OPTIONAL_FIELDS:
            return _OPTIONAL_FIELDS[name]
        if name in fields:
            v = fields[name]
            if isinstance(v, list):
                return tuple(v)
            if isinstance(v, dict):
                return _json.loads(_json.dumps(v))
            return v
        raise AttributeError(f"Atmosphere has no field '{name}' (fields: {', '.join(fields)})")

    def __setattr__(self, name, value):
        new = self.replace(**{name: value})
        object.__setattr__(self, "_json", new._json)
        object.__setattr__(self, "_fields", new._fields)

    def __eq__(self, other):
        return isinstance(other, Atmosphere) and self._fields == other._fields

    def __repr__(self):
        return (f"Atmosphere(bottom_radius={self._fields['bottom_radius']}, "
                f"top_radius={self._fields['top_radius']}, "
                f"mie_phase_g={self._fields['mie_phase_g']})")


def _check_finite(field, v):
    """JSON has no NaN or infinity: name the field here instead."""
    if isinstance(v, dict):
        for x in v.values():
            _check_finite(field, x)
    elif isinstance(v, (list, tuple, _np.ndarray)):
        for x in v:
            _check_finite(field, x)
    elif isinstance(v, (float, _np.floating)) and not _np.isfinite(v):
        raise ValueError(f"atmosphere field '{field}': {v} is not a finite number")


def _plain(v):
    """NumPy values and tuples as JSON-able Python values."""
    if isinstance(v, _np.ndarray):
        return v.tolist()
    if isinstance(v, (_np.floating, _np.integer)):
        return v.item()
    if isinstance(v, (tuple, list)):
        return [_plain(x) for x in v]
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    return v


def _option_text(name, value):
    """A keyword option's value as the text NAME:OPTION=VALUE takes."""
    if isinstance(value, bool):
        raise ValueError(f"option {name}: give a number or a choice word, not {value!r}")
    if isinstance(value, (int, _np.integer)):
        return str(int(value))
    if isinstance(value, (float, _np.floating)):
        return repr(float(value))  # the shortest text that reads back to the same double
    if isinstance(value, (str, _os.PathLike)):
        return _os.fspath(value)
    raise ValueError(f"option {name}: expected a number or text, got {type(value).__name__}")


class Model:
    """A model with options: Model("bruneton", orders=4) or
    Model("bruneton:orders=4"). Keyword names take '_' for '-'
    (light_steps= is light-steps); the model's option table validates them
    (ValueError with the command line's message)."""

    def __init__(self, name, **options):
        given = {}
        for k, v in options.items():
            key = k.replace("_", "-")
            given[key] = _option_text(key, v)
        self._m = _atmos._Model(name, given)
        self._atmosphere = None

    @property
    def name(self):
        return self._m.name

    @property
    def spec(self):
        """NAME:OPTION=VALUE... as given (the command line's --model text)."""
        return self._m.spec

    @property
    def info(self):
        return self._m.info

    @property
    def atmosphere(self):
        """The Atmosphere of the last prepare() (None before)."""
        return self._atmosphere

    def options(self):
        """Every option with its value (defaults included), in table order."""
        return dict(self._m.options())

    def prepare(self, atmosphere="earth"):
        """Precomputes for the atmosphere (an Atmosphere, or anything
        Atmosphere.load takes). Returns self."""
        atm = Atmosphere.load(atmosphere)
        self._m.prepare(atm._json)
        self._atmosphere = atm
        return self

    def load_baked(self, directory, atmosphere="earth"):
        """Reads tables written by bake() / `atmos bake` instead of prepare()."""
        atm = Atmosphere.load(atmosphere)
        self._m.load_baked(_os.fspath(directory), atm._json)
        self._atmosphere = atm
        return self

    def bake(self, directory):
        """Writes the tables of the last prepare() (EXR + JSON) to a directory."""
        _os.makedirs(_os.fspath(directory), exist_ok=True)
        self._m.bake(_os.fspath(directory))

    def sample(self, altitude, mu, mu_s, azimuth=0.0, *, spp=None, seed=None, strict=False):
        """Radiance per unit solar irradiance and transmittance at queries of
        `atmos sample` (camera at altitude metres, view cosine mu, sun cosine
        mu_s, sun azimuth in degrees). The four arguments broadcast as NumPy
        arrays; returns (L, T), float32 arrays of the broadcast shape + (3,).
        float64 arrays are read in place (any strides); the GIL is released.
        Monte Carlo models take spp (paths per query) and seed."""
        args = [_np.asarray(a, dtype=_np.float64) for a in (altitude, mu, mu_s, azimuth)]
        return _guarded(lambda: self._m.sample(*args, spp=spp, seed=seed), strict)

    def render(self, view="ground-noon", size=(480, 270), *, quantity="radiance",
               sun_disc=False, spp=None, seed=None, pass_spp=None, checkpoint=None,
               resume=False, return_variance=False, progress=None, strict=False):
        """Renders a standard view: float32 array H x W x 3 (linear, as the
        EXR of `atmos render`). Monte Carlo models (the reference) take spp,
        seed, pass_spp, checkpoint (a file stem), resume and return_variance
        (then returns (image, variance)); `progress` is a callable
        progress(passes_done, passes) called after each pass, or True for a
        tqdm bar when tqdm is installed."""
        width, height = size
        callback, bar = _progress_callback(progress)
        try:
            return _guarded(lambda: self._m.render(
                view, int(width), int(height), quantity, bool(sun_disc), spp, seed, pass_spp,
                "" if checkpoint is None else _os.fspath(checkpoint), bool(resume),
                bool(return_variance), callback), strict)
        finally:
            if bar is not None:
                bar.close()

    def __repr__(self):
        return f"atmos.Model({self.spec!r})"


def _guarded(call, strict):
    """Runs call(); when it made the output guard replace values (NaN,
    infinite or negative, written as 0), warns as the CLI does, or raises
    ValueError when strict (the CLI's --strict exits 2)."""
    before = _atmos.output_guard_count()
    result = call()
    replaced = _atmos.output_guard_count() - before
    if replaced > 0:
        message = (f"atmos: {replaced} output value(s) were NaN, infinite or negative and were "
                   "written as 0 (a defect: please report it with the call)")
        if strict:
            raise ValueError(message)
        _warnings.warn(message, RuntimeWarning, stacklevel=3)
    return result


def _progress_callback(progress):
    if progress is None or progress is False:
        return None, None
    if progress is True:
        try:
            from tqdm import tqdm
        except ImportError:
            return None, None
        bar = tqdm(total=None, unit="pass")

        def update(done, total):
            bar.total = total
            bar.n = done
            bar.refresh()
        return update, bar
    if not callable(progress):
        raise TypeError("progress: expected a callable progress(done, total), True or None")
    return progress, None


FlipResult = collections.namedtuple("FlipResult", "mean map hdr start_exposure stop_exposure "
                                    "num_exposures")
RmseResult = collections.namedtuple("RmseResult", "channel overall mse psnr")


def _is_png(x):
    return isinstance(x, (str, _os.PathLike)) and _os.fspath(x).lower().endswith(".png")


def _image_arg(x):
    return _os.fspath(x) if isinstance(x, (str, _os.PathLike)) else x


def flip(reference, test, *, mode="auto", ppd=0.0, tonemapper="aces", start_exposure=None,
         stop_exposure=None, num_exposures=0):
    """FLIP of two images (arrays H x W x 3, or file names), as `atmos flip`:
    HDR-FLIP unless mode="ldr" or (auto) the reference is a PNG file. Returns
    FlipResult(mean, map (H x W float32), hdr, start_exposure, stop_exposure,
    num_exposures)."""
    if mode not in ("auto", "ldr", "hdr"):
        raise ValueError("mode must be auto, ldr or hdr")
    hdr = mode == "hdr" or (mode == "auto" and not _is_png(reference))
    r = _atmos.flip(_image_arg(reference), _image_arg(test), hdr, float(ppd), tonemapper,
                    start_exposure, stop_exposure, int(num_exposures))
    return FlipResult(*r)


def rmse(reference, test, *, peak=1.0):
    """RMSE per channel and overall, MSE and PSNR (dB, for a signal `peak`) of
    two images (arrays or file names), as `atmos rmse`."""
    channel, overall, mse, psnr = _atmos.rmse(_image_arg(reference), _image_arg(test),
                                              float(peak))
    return RmseResult(channel, overall, mse, psnr)


def bake(model, directory, atmosphere="earth", **options):
    """Precomputes a model (a Model, or a name with keyword options) for the
    atmosphere and writes its tables to `directory`, as `atmos bake`.
    Returns the prepared Model."""
    m = model if isinstance(model, Model) else Model(model, **options)
    if not m._m.can_bake():
        raise ValueError(f"model {m.spec} has no precomputed tables to bake")
    if m.atmosphere is None or m.atmosphere != Atmosphere.load(atmosphere):
        m.prepare(atmosphere)
    m.bake(directory)
    return m

