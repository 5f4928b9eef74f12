"""The atmos Python module against the atmos CLI (the same library): answers
bit for bit, shapes and broadcasting, errors, renders, metrics, memory."""

import gc
import os

import numpy as np
import pytest

import atmos


# ---- names, option tables, atmospheres ---------------------------------------------------------


def test_models_and_their_option_tables_match_the_cli(cli):
    names = atmos.models()
    for expected in ("naive", "bruneton", "reference"):
        assert expected in names
    rc, out, _ = cli("list", "bruneton")
    assert rc == 0
    info = atmos.model_info("bruneton")
    assert info["name"] == "bruneton"
    assert info["capabilities"]["precomputed"]
    orders = [o for o in info["options"] if o["name"] == "orders"]
    assert len(orders) == 1
    o = orders[0]
    assert o["type"] == "integer" and o["min"] <= int(o["default"]) <= o["max"]
    assert set(o) >= {"name", "type", "default", "range", "help"}
    for opt in info["options"]:  # every option the CLI lists, with its help
        assert opt["name"] in out and opt["help"].split()[0] in out
    assert atmos.model_info("reference")["capabilities"]["stochastic"]


def test_unknown_model_is_a_value_error(cli):
    with pytest.raises(ValueError, match="nope"):
        atmos.model_info("nope")
    with pytest.raises(ValueError) as e:
        atmos.Model("nope")
    rc, _, err = cli("sample", "-m", "nope", stdin="altitude_m,mu,mu_s,azimuth_deg\n")
    assert rc != 0 and str(e.value) in err


def test_option_errors_carry_the_cli_message(cli):
    for kwargs, spec in (({"orders": 99}, "bruneton:orders=99"),
                         ({"orders": 2.5}, "bruneton:orders=2.5"),
                         ({"bogus": 1}, "bruneton:bogus=1")):
        with pytest.raises(ValueError) as e:
            atmos.Model("bruneton", **kwargs)
        rc, _, err = cli("sample", "-m", spec, stdin="altitude_m,mu,mu_s,azimuth_deg\n")
        assert rc == 2
        assert err.strip() == "atmos: error: " + str(e.value)
    with pytest.raises(ValueError):
        atmos.Model("naive", steps=True)
    # Keywords take '_' for '-'; a spec string works as on the command line.
    m = atmos.Model("naive", light_steps=4)
    assert m.options()["light-steps"] == 4
    assert atmos.Model("naive:steps=8").options()["steps"] == 8


def test_atmosphere_load_fields_and_validation(tmp):
    earth = atmos.Atmosphere.load("earth")
    assert earth.bottom_radius == 6360e3
    assert len(earth.rayleigh_scattering) == 3
    assert "layers" in earth.mie_density
    assert set(atmos.atmosphere_presets()) >= {"earth"}
    # dict and file round trips
    assert atmos.Atmosphere.load(earth.to_dict()) == earth
    path = tmp / "a.json"
    path.write_text(earth.to_json())
    assert atmos.Atmosphere.load(path) == earth
    # validation errors name the field
    d = earth.to_dict()
    d["mie_phase_g"] = 1.5
    with pytest.raises(ValueError, match="mie_phase_g"):
        atmos.Atmosphere.load(d)
    with pytest.raises(ValueError, match="top_radius"):
        earth.replace(top_radius=1.0)
    with pytest.raises(ValueError, match="ground_albedo"):
        earth.ground_albedo = (0.1, float("nan"), 0.1)
    del d["mie_phase_g"]
    with pytest.raises(ValueError, match="mie_phase_g"):
        atmos.Atmosphere.load(d)
    with pytest.raises(ValueError, match="no_such_field"):
        earth.replace(no_such_field=1)
    with pytest.raises(ValueError, match="unknown atmosphere"):
        atmos.Atmosphere.load("no-such-preset")
    with pytest.raises(AttributeError):
        earth.not_a_field
    g = earth.replace(mie_phase_g=np.float64(0.7))
    assert g.mie_phase_g == 0.7 and earth.mie_phase_g != 0.7
    assert atmos.Atmosphere.load("earth", ["mie_phase_g=0.7"]) == g
    # The second Mie lobe: absent from one-lobe JSON, read as 0, settable.
    assert "mie_phase_weight2" not in earth.to_dict()
    assert earth.mie_phase_weight2 == 0.0 and earth.mie_phase_g2 == 0.0
    two = earth.replace(mie_phase_g2=0.9, mie_phase_weight2=0.25)
    assert two.mie_phase_g2 == 0.9 and two.mie_phase_weight2 == 0.25
    assert atmos.Atmosphere.load("earth", ["mie_phase_g2=0.9", "mie_phase_weight2=0.25"]) == two
    with pytest.raises(ValueError, match="mie_phase_weight2"):
        earth.replace(mie_phase_weight2=1.5)

    # Other phase kinds (issue 32 item 4): a kind name or a table, read back as given.
    assert earth.mie_phase == "cornette-shanks"
    iso = earth.replace(mie_phase="isotropic")
    assert iso.mie_phase == "isotropic" and "mie_phase_g" not in iso.to_dict()
    table = {"kind": "tabulated", "angles_deg": [0, 90, 180], "values": [4.0, 1.0, 2.0]}
    tab = earth.replace(mie_phase=table)
    assert tab.mie_phase == table and "mie_phase=tabulated" in repr(tab)
    assert atmos.Atmosphere.load(tab.to_dict()) == tab
    with pytest.raises(ValueError, match="mie_phase.values"):
        earth.replace(mie_phase={"kind": "tabulated", "angles_deg": [0, 180], "values": [1, -1]})


# ---- sample: bit for bit with `atmos sample` -------------------------------------------------


def _queries(n, seed):
    rng = np.random.default_rng(seed)
    alt = rng.choice([0.0, 10.0, 1500.0, 12e3, 80e3, 300e3], n)
    mu = rng.uniform(-1.0, 1.0, n)
    mu_s = rng.uniform(-0.3, 1.0, n)
    az = rng.uniform(0.0, 360.0, n)
    return alt, mu, mu_s, az


def _cli_sample(cli, spec, q, *flags):
    lines = ["altitude_m,mu,mu_s,azimuth_deg"]
    lines += [",".join(repr(float(v)) for v in row) for row in zip(*q)]
    rc, out, err = cli("sample", "-q", "-m", spec, *flags, stdin="\n".join(lines) + "\n")
    assert rc == 0, err
    rows = out.strip().splitlines()[1:]
    table = np.array([[np.float32(float(x)) for x in r.split(",")[4:]] for r in rows],
                     dtype=np.float32)
    return table[:, 0:3], table[:, 3:6]


# Bruneton with small tables: a precomputed model that prepares in well under a second.
SMALL_BRUNETON = ("bruneton:orders=2:scattering-samples=4:transmittance-width=32:"
                  "transmittance-height=8:irradiance-width=8:irradiance-height=4:scattering-r=4:"
                  "scattering-mu=16:scattering-mu-s=4:scattering-nu=2")


@pytest.mark.parametrize("spec", ["naive", "naive:steps=8:light-steps=3", SMALL_BRUNETON])
def test_sample_equals_the_cli_bit_for_bit(cli, spec):
    q = _queries(200, 1)
    m = atmos.Model(spec).prepare("earth")
    L, T = m.sample(*q)
    assert L.dtype == np.float32 and L.shape == (200, 3) and T.shape == (200, 3)
    cl, ct = _cli_sample(cli, spec, q)
    assert np.array_equal(L, cl)
    assert np.array_equal(T, ct)
    assert np.all(np.isfinite(L)) and np.all(L >= 0)


def test_monte_carlo_sample_equals_the_cli_bit_for_bit(cli):
    q = _queries(40, 2)
    m = atmos.Model("reference").prepare("earth")
    L, T = m.sample(*q, spp=8, seed=5)
    cl, ct = _cli_sample(cli, "reference", q, "--spp", "8", "--seed", "5")
    assert np.array_equal(L, cl) and np.array_equal(T, ct)
    L2, _ = m.sample(*q, spp=8, seed=6)
    assert not np.array_equal(L, L2)
    with pytest.raises(ValueError, match="Monte Carlo"):
        atmos.Model("naive").prepare().sample(0.0, 0.5, 0.5, spp=4)
    with pytest.raises(ValueError, match="spp"):
        m.sample(0.0, 0.5, 0.5, spp=0)


# ---- shapes, broadcasting, strides ------------------------------------------------------------


def test_broadcasting_and_strides():
    m = atmos.Model("naive", steps=8, light_steps=4).prepare()
    mu = np.linspace(-0.2, 1.0, 6).reshape(6, 1)
    mu_s = np.linspace(-0.1, 1.0, 4)
    L, T = m.sample(500.0, mu, mu_s, 30.0)
    assert L.shape == (6, 4, 3) and T.shape == (6, 4, 3)
    # each element equals the query made alone
    for i in range(6):
        for j in range(4):
            l1, t1 = m.sample([500.0], [mu[i, 0]], [mu_s[j]], [30.0])
            assert np.array_equal(L[i, j], l1[0]) and np.array_equal(T[i, j], t1[0])
    # scalars give shape (3,); lists and ints are converted
    l0, t0 = m.sample(0, 1, 1, 0)
    assert l0.shape == (3,) and t0.shape == (3,)
    # non-contiguous and reversed views read through their strides
    big = np.linspace(-1.0, 1.0, 40)
    Lv, _ = m.sample(0.0, big[::3], 0.5, 0.0)
    Lc, _ = m.sample(0.0, np.ascontiguousarray(big[::3]), 0.5, 0.0)
    assert np.array_equal(Lv, Lc)
    Lr, _ = m.sample(0.0, big[::-1], 0.5, 0.0)
    assert np.array_equal(Lr, m.sample(0.0, big, 0.5, 0.0)[0][::-1])
    grid = np.asfortranarray(np.linspace(0, 1, 12).reshape(3, 4))
    Lf, _ = m.sample(0.0, grid, 0.3, 0.0)
    assert np.array_equal(Lf, m.sample(0.0, np.ascontiguousarray(grid), 0.3, 0.0)[0])
    # empty input, empty output
    le, _ = m.sample(np.zeros((0, 2)), 0.5, 0.5, 0.0)
    assert le.shape == (0, 2, 3)
    with pytest.raises(ValueError, match="broadcast"):
        m.sample(np.zeros(3), np.zeros(4), 0.5, 0.0)


def test_bad_queries_are_value_errors():
    m = atmos.Model("naive").prepare()
    with pytest.raises(ValueError, match="mu is not a finite number.*index 2"):
        m.sample(0.0, [0.1, 0.2, np.nan], 0.5, 0.0)
    with pytest.raises(ValueError, match="azimuth is not a finite"):
        m.sample(0.0, 0.1, 0.5, np.inf)
    with pytest.raises(ValueError, match="altitude must be >= 0"):
        m.sample(-1.0, 0.1, 0.5, 0.0)
    with pytest.raises(ValueError, match=r"mu_s must be in \[-1, 1\]"):
        m.sample(0.0, 0.1, 1.5, 0.0)
    with pytest.raises(ValueError, match="prepare"):
        atmos.Model("naive").sample(0.0, 0.1, 0.5, 0.0)
    with pytest.raises(ValueError):
        m.sample(0.0, "x", 0.5, 0.0)


# ---- render, the path tracer, progress ----------------------------------------------------------


def test_render_equals_the_cli_exr(cli, tmp):
    m = atmos.Model("naive").prepare()
    img = m.render(view="ground-sunrise", size=(32, 18))
    assert img.dtype == np.float32 and img.shape == (18, 32, 3)
    out = tmp / "n.exr"
    rc, _, err = cli("render", "-q", "-m", "naive", "-v", "ground-sunrise", "-s", "32x18",
                     "-o", str(out))
    assert rc == 0, err
    assert np.array_equal(img, atmos.read_image(out))
    t = m.render(view="space", size=(16, 9), quantity="transmittance")
    rc, _, err = cli("render", "-q", "-m", "naive", "-v", "space", "-s", "16x9",
                     "--quantity", "transmittance", "-o", str(tmp / "t.exr"))
    assert rc == 0, err
    assert np.array_equal(t, atmos.read_image(tmp / "t.exr"))
    with pytest.raises(ValueError, match="ground-noon"):
        m.render(view="nowhere")
    with pytest.raises(ValueError, match="size"):
        m.render(size=(0, 10))


def test_path_tracer_render_equals_the_cli_and_reports_progress(cli, tmp):
    m = atmos.Model("reference").prepare()
    calls = []
    img, var = m.render(view="ground-noon", size=(12, 8), spp=8, pass_spp=2, seed=3,
                        return_variance=True, progress=lambda d, n: calls.append((d, n)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
    assert var.shape == img.shape and np.all(var >= 0)
    out = tmp / "r.exr"
    rc, _, err = cli("render", "-q", "-m", "reference", "-v", "ground-noon", "-s", "12x8",
                     "--spp", "8", "--pass-spp", "2", "--seed", "3", "-o", str(out))
    assert rc == 0, err
    assert np.array_equal(img, atmos.read_image(out))

    def stop(done, total):
        if done == 2:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        m.render(size=(12, 8), spp=8, pass_spp=2, progress=stop)
    with pytest.raises(ValueError, match="Monte Carlo"):
        atmos.Model("naive").prepare().render(size=(4, 4), spp=4)


# ---- metrics, views, bake -------------------------------------------------------------------------


def test_flip_and_rmse_match_the_cli(cli, tmp):
    a = atmos.Model("naive").prepare().render(size=(24, 16))
    b = atmos.Model("naive", steps=4, light_steps=2).prepare().render(size=(24, 16))
    atmos.write_image(a, tmp / "a.exr")
    atmos.write_image(b, tmp / "b.exr")
    f = atmos.flip(a, b)
    assert f.hdr and f.map.shape == (16, 24) and 0.0 < f.mean < 1.0
    rc, out, _ = cli("flip", str(tmp / "a.exr"), str(tmp / "b.exr"))
    assert rc == 0
    assert f"mean FLIP: {f.mean:.6f}" in out
    assert atmos.flip(tmp / "a.exr", tmp / "b.exr").mean == f.mean
    assert atmos.flip(a, a).mean == 0.0
    assert atmos.flip(a, b, mode="ldr").hdr is False
    r = atmos.rmse(a, b)
    rc, out, _ = cli("rmse", str(tmp / "a.exr"), str(tmp / "b.exr"))
    assert rc == 0 and f"RMSE: {r.overall:.8g}" in out
    assert atmos.rmse(a, a).psnr == float("inf")
    with pytest.raises(ValueError, match="ppd"):
        atmos.flip(a, b, ppd=1e12)
    with pytest.raises(ValueError):
        atmos.rmse(a, b[:8])


def test_views():
    v = atmos.views()
    assert [x["name"] for x in v] == atmos.view_names()
    assert len(v) == 12
    noon = [x for x in v if x["name"] == "ground-noon"][0]
    assert abs(np.linalg.norm(noon["sun_direction"]) - 1.0) < 1e-12


def test_bake_and_load_baked_give_the_same_answers(tmp):
    m = atmos.bake(atmos.Model(SMALL_BRUNETON), tmp / "baked")
    assert (tmp / "baked").is_dir() and any((tmp / "baked").iterdir())
    q = _queries(50, 3)
    loaded = atmos.Model(SMALL_BRUNETON).load_baked(tmp / "baked", "earth")
    assert np.array_equal(m.sample(*q)[0], loaded.sample(*q)[0])
    with pytest.raises(ValueError, match="no precomputed tables"):
        atmos.bake("naive", tmp / "x")


# ---- memory ---------------------------------------------------------------------------------------


def _rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs /proc")
def test_memory_does_not_grow_over_1000_calls():
    m = atmos.Model("naive", steps=2, light_steps=1).prepare()
    mu = np.linspace(-1.0, 1.0, 1000)

    def calls(n):
        for _ in range(n):
            L, T = m.sample(0.0, mu, 0.5, 0.0)
            img = m.render(size=(32, 32))
            try:
                m.sample(0.0, np.nan, 0.5, 0.0)
            except ValueError:
                pass
        del L, T, img
        gc.collect()
    calls(50)  # warm up allocators and caches
    before = _rss_bytes()
    calls(1000)
    grown = _rss_bytes() - before
    # 1000 calls allocate 1000 x (24 KB of answers + 12 KB image): a leak of any
    # of them would grow by >= 12 MB.
    assert grown < 4 * 1024 * 1024, f"RSS grew by {grown / 1e6:.1f} MB over 1000 calls"


# --- Issue 33 item 5 and item 4 (the table cache from Python).

def test_render_arguments_are_checked():
    m = atmos.Model("naive", steps=4, light_steps=2).prepare()
    with pytest.raises(ValueError, match="view"):
        m.render(view={"camera": [0, 0, 1]}, size=(8, 4))
    with pytest.raises(ValueError, match="size"):
        m.render(size=16)
    with pytest.raises(ValueError, match="size"):
        m.render(size=(8.5, 4))


def test_flip_names_the_channel_count():
    a = np.zeros((4, 4, 3), np.float32)
    with pytest.raises(ValueError, match="4 channels"):
        atmos.flip(a, np.zeros((4, 4, 4), np.float32))


def test_write_image_refuses_what_the_cli_never_writes(tmp_path):
    good = np.full((2, 3, 3), 0.5, np.float32)
    atmos.write_image(good, tmp_path / "ok.exr")
    for bad, what in ((np.nan, "NaN"), (np.inf, "infinite"), (-1.0, "negative")):
        img = good.copy()
        img[1, 2, 0] = bad
        path = tmp_path / "bad.exr"
        with pytest.raises(ValueError, match=what):
            atmos.write_image(img, path)
        assert not path.exists()


def test_version_and_typed_options():
    assert isinstance(atmos.__version__, str) and atmos.__version__.count(".") == 2
    o = atmos.Model("bruneton").options()
    assert isinstance(o["orders"], int)
    assert isinstance(o["mie-storage"], str)
    assert isinstance(atmos.Model("hillaire").options()["segment-offset"], float)


def test_to_srgb_is_the_png_curve():
    x = np.array([[[0.0, 0.001, 1.0]]], np.float32)
    y = atmos.to_srgb(x)
    assert y.dtype == np.float32 and y.shape == x.shape
    t = 1.0 - np.exp(-1.0)
    assert y[0, 0, 0] == 0.0
    assert abs(y[0, 0, 1] - 12.92 * (1.0 - np.exp(-0.001))) < 1e-6
    assert abs(y[0, 0, 2] - (1.055 * t ** (1 / 2.4) - 0.055)) < 1e-6
    assert atmos.to_srgb(x, exposure=2.0)[0, 0, 2] > y[0, 0, 2]


def test_prepare_uses_the_table_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv("ATMOS_NO_CACHE", "0")
    m = atmos.Model("hillaire")
    assert m._m.prepare(atmos.Atmosphere.load("earth")._json, True) is False  # computed, stored
    assert (tmp_path / "atmos" / "tables").is_dir()
    again = atmos.Model("hillaire")
    assert again._m.prepare(atmos.Atmosphere.load("earth")._json, True) is True  # loaded
    a = m.render(view="ground-sunrise", size=(16, 9))
    b = again.render(view="ground-sunrise", size=(16, 9))
    assert a.tobytes() == b.tobytes()
    assert atmos.Model("hillaire")._m.prepare(atmos.Atmosphere.load("earth")._json, False) is False


def test_the_output_guard_warns_or_raises_like_the_cli():
    """Issue 39 item 4: values the guard replaced are counted and reported (a
    RuntimeWarning; ValueError under strict=True, the CLI's --strict), never
    zeroed silently."""
    import warnings
    from atmos import _atmos
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        atmos._guarded(lambda: _atmos._guard_nan_for_test(3), False)
    assert len(caught) == 1 and issubclass(caught[0].category, RuntimeWarning)
    assert "3 output value(s)" in str(caught[0].message)
    with pytest.raises(ValueError, match="2 output value"):
        atmos._guarded(lambda: _atmos._guard_nan_for_test(2), True)
    # A clean call says nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = atmos.Model("flat").prepare("earth")
        m.sample(0.0, 0.5, 0.5, strict=True)
        m.render(size=(8, 4), strict=True)
