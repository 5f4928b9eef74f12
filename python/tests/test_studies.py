"""The studies from Python (atmos.validate, atmos.compare, atmos.bench): the
library's run in-process, no subprocess; small inputs and cheap models."""

import math
import pathlib

import numpy as np
import pytest

import atmos

KIDER = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "kider-2013"


def test_validate_returns_values_and_the_errors_they_give():
    r = atmos.validate(["flat"], data=KIDER, captures="12:45")
    assert r["wavelengths"].shape == (40,)
    assert r["measured"].shape == (80, 40)
    assert r["fit"] is None
    flat = r["models"]["flat"]
    assert flat["values"].shape == (80, 40)
    assert np.all(np.isfinite(flat["values"]))
    pooled = [e for e in flat["errors"]
              if (e["capture"], e["scope"], e["region"]) == ("all", "all", "all")]
    assert len(pooled) == 1
    # The pooled row recomputed here from the arrays.
    d = flat["values"] - r["measured"]
    expected = math.sqrt(float(np.mean(d * d))) / float(np.mean(r["measured"]))
    assert pooled[0]["relative_rmse"] == pytest.approx(expected, rel=1e-12)
    assert pooled[0]["count"] == 80 * 40
    assert r["errors_csv"].startswith("model,capture,scope,region,rel_rmse_percent")


def test_validate_errors_are_value_errors():
    with pytest.raises(ValueError, match="--captures '23:59'"):
        atmos.validate(["flat"], data=KIDER, captures=["23:59"])
    with pytest.raises(ValueError):
        atmos.validate(["no-such-model"], data=KIDER)


def test_compare_returns_the_tables(tmp):
    r = atmos.compare(tmp / "cmp", ["flat", "empty"], views=["ground-noon", "space"],
                      size=(16, 9), reference="naive:steps=8", no_cache=True, npy=False)
    assert r["models"] == ["flat", "empty"]
    assert r["views"] == ["ground-noon", "space"]
    assert r["reference"] == "naive"
    assert r["flip"].shape == (2, 2) and r["rmse"].shape == (2, 2)
    assert np.all(r["flip"] >= 0) and np.all(np.isfinite(r["flip"]))
    # empty (constant white) is further from the reference than flat on the ground.
    assert r["rmse"][0, 1] > r["rmse"][0, 0]
    flip_csv = (tmp / "cmp" / "flip.csv").read_text().splitlines()
    assert flip_csv[0] == "FLIP errors,flat,empty,best"
    assert float(flip_csv[1].split(",")[1]) == pytest.approx(r["flip"][0, 0], rel=1e-7)


def test_compare_custom_views_regions_regimes_and_luminance(tmp):
    views = {"sky-5deg": {"camera": {"projection": "equirect"},
                          "sun": {"elevation": 5, "azimuth": 90}}}
    r = atmos.compare(tmp / "custom", ["naive:steps=8", "empty"], views=views, size=(8, 4),
                      reference="naive:steps=8", no_cache=True, npy=False, luminance=True)
    assert r["views"] == ["sky-5deg"]
    # The reference itself: zero over the sky and the ground alike.
    assert r["flip_sky"][0, 0] == 0 and r["rmse_ground"][0, 0] == 0
    assert r["rmse_sky"][0, 1] > 0
    # empty is grey, 1 per unit irradiance: the Sun's illuminance per steradian (~1.3e5).
    assert 1.2e5 < r["luminance"][0, 1] < 1.4e5
    assert r["reference_luminance"][0] == pytest.approx(r["luminance"][0, 0])
    assert [(g["kind"], g["regime"]) for g in r["regimes"]] == [("place", "ground"),
                                                                ("light", "sunrise")]
    assert r["regimes"][0]["best"] == ["naive:steps=8"]  # empty: a baseline, left out
    assert (tmp / "custom" / "regimes.csv").exists()
    with pytest.raises(ValueError, match="view 'x', camera: fov must be in"):
        atmos.compare(tmp / "bad", ["empty"], views={"x": {"camera": "fov=200", "sun": "elevation=5"}},
                      size=(8, 4), reference="naive:steps=8", no_cache=True)


def test_bench_times_each_model_and_view():
    r = atmos.bench(["flat", "empty"], views=["ground-noon"], size=(8, 4), repeat=2, warmup=0)
    assert [(row["model"], row["view"]) for row in r["rows"]] == [
        ("flat", "ground-noon"), ("empty", "ground-noon")]
    for row in r["rows"]:
        assert row["runs"] == 2
        assert 0 < row["render_min_s"] <= row["render_median_s"] <= row["render_max_s"]
    assert r["csv"].count("\n") == 3
    with pytest.raises(ValueError, match="Monte Carlo"):
        atmos.bench(["flat"], views=["ground-noon"], size=(8, 4), spp=4)
