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
from ._sun import sun_position

__all__ = [
    "Atmosphere", "Model", "Camera", "FlipResult", "RmseResult", "models", "model_info", "views",
    "view_names", "atmosphere_presets", "flip", "rmse", "bake", "read_image", "write_image",
    "set_threads", "thread_count", "sun_position", "to_srgb", "validate", "compare", "bench",
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
    (.exr .png .npy .pfm); `exposure` applies to PNG only. Refuses (ValueError)
    NaN, infinite or negative values, as the command line never writes them."""
    _check_image_values(image)
    _atmos.write_image(image, _os.fspath(path), float(exposure))


def set_threads(threads):
    """Limits the worker threads of every later call (0: all cores)."""
    _atmos.set_threads(int(threads))


def thread_count():
    """The number of worker threads calls use now."""
    return _atmos.thread_count()


# Fields the JSON text leaves out at their default (the second Mie lobe,
# written only when it has a weight; the phase function's kind, written only
# when it is not Cornette-Shanks): read as attributes, settable by replace().
_OPTIONAL_FIELDS = {"mie_phase_g2": 0.0, "mie_phase_weight2": 0.0,
                    "mie_phase": "cornette-shanks"}


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
        phase = self.mie_phase
        kind = phase["kind"] if isinstance(phase, dict) else phase
        last = (f"mie_phase_g={self._fields['mie_phase_g']}" if "mie_phase_g" in self._fields
                else f"mie_phase={kind}")
        return (f"Atmosphere(bottom_radius={self._fields['bottom_radius']}, "
                f"top_radius={self._fields['top_radius']}, {last})")


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
        """Every option with its value (defaults included), in table order:
        integers as int, reals as float, choices and text as str."""
        return _typed_options(self.info, self._m.options())

    def prepare(self, atmosphere="earth", *, cache=True):
        """Precomputes for the atmosphere (an Atmosphere, or anything
        Atmosphere.load takes). Returns self. Models with tables read them from
        the user's table cache when an entry of the same model, table-shaping
        options, atmosphere and build exists, and store them there otherwise
        ($XDG_CACHE_HOME/atmos/tables; cache=False or ATMOS_NO_CACHE=1:
        neither)."""
        atm = Atmosphere.load(atmosphere)
        self._m.prepare(atm._json, bool(cache))
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

    def sample(self, altitude, mu, mu_s, azimuth=0.0, *, spp=None, seed=None, ground=False,
               sun_disc=False, strict=False):
        """Radiance per unit solar irradiance and transmittance at queries of
        `atmos sample` (camera at altitude metres, view cosine mu, sun cosine
        mu_s, sun azimuth in degrees). The four arguments broadcast as NumPy
        arrays; returns (L, T), float32 arrays of the broadcast shape + (3,).
        float64 arrays are read in place (any strides); the GIL is released.
        Monte Carlo models take spp (paths per query) and seed. ground=True
        adds the lit ground and sun_disc=True the sun's disc, as a rendered
        pixel shows them (`atmos sample --ground --sun-disc`)."""
        args = [_np.asarray(a, dtype=_np.float64) for a in (altitude, mu, mu_s, azimuth)]
        return _guarded(lambda: self._m.sample(*args, spp=spp, seed=seed, ground=bool(ground),
                                               sun_disc=bool(sun_disc)), strict)

    def irradiance(self, sun, altitude=0.0):
        """The sun's direct and the sky's diffuse irradiance on a horizontal
        plane at `altitude` metres (`atmos irradiance`): a dict with 'direct',
        'diffuse' (the converged hemisphere integral of the model's radiance),
        'diffuse_coarse' (the same at half the nodes), 'nodes' and
        'diffuse_table' (bruneton's irradiance table, else None); RGB tuples
        per unit solar irradiance times the atmosphere's solar_irradiance.
        `sun` is (elevation_deg, azimuth_deg) or "elevation=DEG,azimuth=DEG"."""
        return self._m.irradiance(_sun_text(sun), float(altitude))

    def render(self, view="ground-noon", size=(480, 270), *, camera=None, sun=None,
               quantity="radiance", sun_disc=False, spp=None, seed=None, pass_spp=None,
               checkpoint=None, resume=False, return_variance=False, progress=None,
               strict=False):
        """Renders a standard view, or a free `camera` (atmos.Camera) with a
        `sun` (elevation_deg, azimuth_deg): float32 array H x W x 3 (linear,
        as the EXR of `atmos render`; docs/views.md gives the projections).
        Monte Carlo models (the reference) take spp, seed, pass_spp,
        checkpoint (a file stem), resume and return_variance (then returns
        (image, variance)); `progress` is a callable progress(passes_done,
        passes) called after each pass, or True for a tqdm bar when tqdm is
        installed."""
        width, height = _check_render_args(view, size)
        camera_text = ""
        if camera is not None:
            if not isinstance(camera, Camera):
                raise ValueError("camera must be an atmos.Camera, got %r" % (camera,))
            camera_text = camera.spec
        sun_text = "" if sun is None else _sun_text(sun)
        if camera is None and sun is not None:
            camera_text = Camera().spec
        callback, bar = _progress_callback(progress)
        try:
            return _guarded(lambda: self._m.render(
                view, int(width), int(height), quantity, bool(sun_disc), spp, seed, pass_spp,
                "" if checkpoint is None else _os.fspath(checkpoint), bool(resume),
                bool(return_variance), callback, camera_text, sun_text), strict)
        finally:
            if bar is not None:
                bar.close()

    def __repr__(self):
        return f"atmos.Model({self.spec!r})"


def _sun_text(sun):
    if isinstance(sun, str):
        return sun
    try:
        values = [float(v) for v in sun]
    except TypeError:
        raise ValueError("sun must be (elevation_deg, azimuth_deg), got %r" % (sun,)) from None
    if len(values) not in (1, 2):
        raise ValueError("sun must be (elevation_deg, azimuth_deg), got %r" % (sun,))
    text = "elevation=%r" % values[0]
    if len(values) == 2:
        text += ",azimuth=%r" % values[1]
    return text


class Camera:
    """A free camera (docs/views.md; the CLI's --camera): altitude (m above
    the ground), azimuth (degrees clockwise from north), elevation, roll, fov
    (perspective: vertical; fisheye: across the height) and projection
    (perspective, equirect, fisheye, cubemap, equal-area). World frame: +x
    east, +y north, +z up. ValueError names the argument and its range."""

    _KEYS = ("altitude", "azimuth", "elevation", "roll", "fov")

    def __init__(self, altitude=0.0, azimuth=None, elevation=None, roll=None, fov=None,
                 projection="perspective"):
        parts = []
        for key, value in zip(self._KEYS, (altitude, azimuth, elevation, roll, fov)):
            if value is None:
                continue
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise ValueError("camera %s must be a number, got %r" % (key, value)) from None
            parts.append("%s=%r" % (key, number))
        if not isinstance(projection, str):
            raise ValueError("camera projection must be a string, got %r" % (projection,))
        parts.append("projection=" + projection)
        self.spec = ",".join(parts)
        _atmos.check_camera(self.spec)
        self.altitude, self.azimuth, self.elevation = altitude, azimuth, elevation
        self.roll, self.fov, self.projection = roll, fov, projection

    def __repr__(self):
        return "atmos.Camera(%s)" % self.spec


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



# --- Issue 33 item 5: argument checks, typed options, the version, a display helper.

__version__ = _atmos.__version__


def _check_render_args(view, size):
    """(width, height) of render()'s size after checking view and size
    (ValueError with the command line's wording)."""
    if not isinstance(view, str):
        raise ValueError(f"view: expected a view name (atmos.view_names()), got "
                         f"{type(view).__name__}")
    try:
        width, height = size
    except (TypeError, ValueError):
        raise ValueError(f"size: expected (width, height), each in [1, 16384], got {size!r}") \
            from None
    for v in (width, height):
        if isinstance(v, bool) or not isinstance(v, (int, _np.integer)) or not 1 <= v <= 16384:
            raise ValueError(f"size: expected (width, height), each an integer in [1, 16384], "
                             f"got {size!r}")
    return int(width), int(height)


def _typed_options(info, pairs):
    types = {o["name"]: o["type"] for o in info["options"]}
    out = {}
    for name, text in pairs:
        kind = types.get(name)
        if kind == "integer":
            out[name] = int(text)
        elif kind == "real":
            out[name] = float(text)
        else:
            out[name] = text
    return out


def _check_image_values(image):
    if isinstance(image, (str, _os.PathLike)):
        return
    a = _np.asarray(image)
    if a.dtype.kind not in "biuf":
        raise ValueError(f"image: expected numbers, got dtype {a.dtype}")
    if a.dtype.kind == "f":
        bad = ~_np.isfinite(a)
        if bad.any():
            raise ValueError(f"image: {int(bad.sum())} values are NaN or infinite (first at "
                             f"index {tuple(int(i) for i in _np.argwhere(bad)[0])})")
    neg = a < 0
    if neg.any():
        raise ValueError(f"image: {int(neg.sum())} values are negative (first at index "
                         f"{tuple(int(i) for i in _np.argwhere(neg)[0])}); radiance is >= 0")


def to_srgb(image, exposure=1.0):
    """A linear radiance image (H x W x 3) as display values in [0, 1] for
    plotting (e.g. matplotlib's imshow), the PNG writer's curve: the exposure,
    the tone map 1 - exp(-x), then the sRGB transfer function (IEC 61966-2-1).
    Returns float32 of the same shape."""
    x = _np.asarray(image, dtype=_np.float64) * float(exposure)
    x = 1.0 - _np.exp(-_np.maximum(_np.nan_to_num(x, nan=0.0, posinf=1e30), 0.0))
    srgb = _np.where(x < 0.0031308, 12.92 * x, 1.055 * _np.power(x, 1.0 / 2.4) - 0.055)
    return _np.clip(srgb, 0.0, 1.0).astype(_np.float32)


# ---- studies (src/atmos/studies/: the same config, policy and run as the CLI) -----------------


def _list(x):
    if x is None:
        return []
    if isinstance(x, str):
        return [i for i in x.split(",") if i]
    return [str(i) for i in x]


def validate(models=None, *, data=None, atmosphere=None, sets=None, captures=None,
             theory_azimuth=False, spp=256, seed=0, fit=False, fit_model=None,
             fit_wavelengths=None, fit_captures=None, fit_evaluations=40,
             fit_second_lobe=False):
    """The validate study, as `atmos validate kider-2013`: spectral models against
    the measured sky of Kider et al. 2014. Returns a dict: wavelengths (40),
    capture and sample (per direction), measured (directions x 40), models
    ({spec: {values: directions x 40, errors: [rows as the CSV], seconds}}), sets,
    fit (None, or the fitted parameters and residuals) and errors_csv (the CSV
    `atmos validate` writes). Defaults are the CLI's (naive and bruneton, the
    kider-2013 atmosphere, ../shared/data/kider-2013)."""
    return _atmos.validate(_list(models), _os.fspath(data) if data else "", atmosphere or "",
                           _list(sets), _list(captures), bool(theory_azimuth), int(spp),
                           int(seed), bool(fit), fit_model or "",
                           [float(v) for v in (fit_wavelengths or [])], _list(fit_captures),
                           int(fit_evaluations), bool(fit_second_lobe))


def compare(output_dir, models=None, *, views=None, size=(320, 180), quantity="radiance",
            reference=None, reference_spp=None, reference_seed=None, reference_noise=None,
            atmosphere="earth", sets=None, cache=None, no_cache=False,
            shipped_references=True, npy=True, progress=False, luminance=False):
    """The compare study, as `atmos compare -o output_dir`: every model against the
    reference (default: the path tracer) at the views; writes the same images,
    tables and index.html. views: names of the 12 and views files (NAME.json), or
    a dict of custom views {name: {"camera": ..., "sun": ...}} (the file's
    format, docs/manual.md). luminance: photopic luminance in cd m^-2 (as
    --luminance). Returns a dict: models, views, reference, flip and rmse (views x
    models), flip_sky, flip_ground, rmse_sky, rmse_ground (NaN where a view has no
    such pixels), reference_noise and reference_spp (per view), regimes (one dict
    per regime), luminance and reference_luminance (with luminance), output_dir."""
    width, height = size
    views_json = ""
    if isinstance(views, dict):
        import json as _json
        views_json, views = _json.dumps(views), None
    return _atmos.compare(_list(models), _list(views), views_json, int(width), int(height),
                          quantity,
                          reference, reference_spp, reference_seed, reference_noise, atmosphere,
                          _list(sets), _os.fspath(output_dir),
                          _os.fspath(cache) if cache is not None else None, bool(no_cache),
                          bool(shipped_references), bool(npy), bool(progress),
                          bool(luminance))


def bench(models=None, *, views=None, size=(480, 270), quantity="radiance", repeat=None,
          warmup=None, prepare_repeat=1, atmosphere="earth", sets=None, spp=None, seed=0,
          wavelengths=None):
    """The bench study, as `atmos bench`: Prepare() and renders timed apart, per
    model and view, on the current backend. Returns a dict: rows (one per model
    and view: prepare_s, render_median_s, ...), stages, spectral (with
    wavelengths), threads, backend and csv (the CSV `atmos bench` writes)."""
    width, height = size
    return _atmos.bench(_list(models), _list(views), int(width), int(height), quantity, repeat,
                        warmup, int(prepare_repeat), atmosphere, _list(sets), spp, int(seed),
                        [float(v) for v in (wavelengths or [])])
