"""Free cameras in Python (issue 31): atmos.Camera, model.render(camera=, sun=),
sample(ground=, sun_disc=), model.irradiance; errors are ValueErrors naming the
argument."""

import numpy as np
import pytest

import atmos


@pytest.fixture(scope="module")
def naive():
    m = atmos.Model("naive", steps=8, light_steps=4)
    m.prepare("earth")
    return m


@pytest.mark.parametrize("projection,size", [("perspective", (16, 9)), ("equirect", (32, 16)),
                                             ("fisheye", (12, 12)), ("cubemap", (48, 8)),
                                             ("equal-area", (12, 12))])
def test_every_projection_renders(naive, projection, size):
    img = naive.render(camera=atmos.Camera(altitude=100.0, projection=projection),
                       sun=(10.0, 45.0), size=size)
    assert img.shape == (size[1], size[0], 3)
    assert np.all(np.isfinite(img)) and np.all(img >= 0) and img.max() > 0


def test_equirect_pixel_equals_sample_with_ground(naive):
    w, h = 32, 16
    img = naive.render(camera=atmos.Camera(projection="equirect"), sun=(10.0, 0.0), size=(w, h))
    # Row y: elevation 90 - 180 (y + 0.5) / H; column 0: azimuth 360 * 0.5 / W from north.
    for y in (2, 12):
        el = np.radians(90.0 - 180.0 * (y + 0.5) / h)
        az = 360.0 * 0.5 / w
        L, _ = naive.sample(0.0, np.sin(el), np.sin(np.radians(10.0)), az, ground=True)
        np.testing.assert_allclose(img[y, 0], L, rtol=2e-4)


def test_camera_errors_name_the_argument():
    with pytest.raises(ValueError, match="camera fov"):
        atmos.Camera(fov=180.0)
    with pytest.raises(ValueError, match="camera altitude"):
        atmos.Camera(altitude=-1.0)
    with pytest.raises(ValueError, match="projection"):
        atmos.Camera(projection="orthographic")
    with pytest.raises(ValueError, match="world-aligned"):
        atmos.Camera(projection="equirect", azimuth=10.0)


def test_render_errors_name_the_argument(naive):
    with pytest.raises(ValueError, match="2:1"):
        naive.render(camera=atmos.Camera(projection="equirect"), sun=(10.0, 0.0), size=(16, 16))
    with pytest.raises(ValueError, match="sun elevation"):
        naive.render(camera=atmos.Camera(), sun=(100.0, 0.0), size=(16, 9))
    with pytest.raises(ValueError, match="camera"):
        naive.render(camera="projection=equirect", sun=(10.0, 0.0), size=(32, 16))


def test_irradiance_matches_the_cli(naive, cli):
    e = naive.irradiance(sun=(30.0, 120.0))
    assert set(e) >= {"direct", "diffuse", "diffuse_table"}
    assert e["diffuse_table"] is None
    rc, out, _ = cli("irradiance", "--model", "naive:steps=8:light-steps=4", "-q", "--sun",
                     "elevation=30,azimuth=120")
    assert rc == 0
    rows = {line.split(",")[0]: [float(v) for v in line.split(",")[1:]]
            for line in out.splitlines()[1:]}
    np.testing.assert_allclose(rows["direct"], e["direct"], rtol=1e-6)
    np.testing.assert_allclose(rows["diffuse"], e["diffuse"], rtol=1e-6)
