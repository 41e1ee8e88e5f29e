# Limit surfaces from Python against closed forms: the uniform square's c, pure translation and
# rotation loads, the inverse, the ellipsoid.
import math

import numpy as np
import pytest

import pushgraph as pg


def test_square_closed_forms():
    a, m, mu = 0.09, 0.8, 0.3
    ls = pg.LimitSurface(pg.Shape.box(a, a), mass=m, mu=mu)
    s = ls.summary
    g = 9.80665
    assert s["f_max"] == pytest.approx(mu * m * g, rel=1e-14)
    # tau_max of a uniform square: mu m g a (sqrt(2) + ln(1 + sqrt(2))) / 6.
    assert s["tau_max"] == pytest.approx(mu * m * g * a * (math.sqrt(2) + math.log(1 + math.sqrt(2))) / 6, rel=1e-13)
    assert s["c"] == pytest.approx(s["tau_max"] / s["f_max"], rel=1e-15)
    loads = ls.sustaining_load([[0.1, 0, 0], [0, 0, 2.0], [0, -0.3, 0]])
    np.testing.assert_allclose(loads, [[s["f_max"], 0, 0], [0, 0, s["tau_max"]], [0, -s["f_max"], 0]], atol=1e-14)


def test_twist_for_load_inverts_the_surface():
    ls = pg.LimitSurface(pg.Shape.from_arrays([[0, 0], [0.1, 0], [0.1, 0.02], [0.02, 0.02], [0.02, 0.08], [0, 0.08]]), 0.5, 0.4)
    rng = np.random.default_rng(2)
    twists = rng.normal(size=(20, 3))
    loads = ls.sustaining_load(twists)
    back = ls.twist_for_load(loads)
    c = ls.summary["c"]
    scaled = twists * np.array([1, 1, c])
    scaled /= np.linalg.norm(scaled, axis=1)[:, None]
    back_scaled = back * np.array([1, 1, c])
    np.testing.assert_allclose(back_scaled / np.linalg.norm(back_scaled, axis=1)[:, None], scaled, atol=1e-6)


def test_ellipsoid_and_bad_input():
    ls = pg.LimitSurface(pg.Shape.disk(0.05), 1.0, 0.5)
    assert ls.ellipsoid.shape == (3, 3)
    err = ls.ellipsoid_error(samples=500)
    assert 0 < err["mean_direction_error_deg"] < 10
    assert ls.ellipsoid_twist([[1.0, 0, 0]]).shape == (1, 3)
    with pytest.raises(pg.LimitSurfaceError, match=r"twists\[1\]"):
        ls.sustaining_load([[1, 0, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match=r"twists\[0\] is not finite"):
        ls.sustaining_load([[np.nan, 0, 0]])
    with pytest.raises(pg.LimitSurfaceError, match="mass"):
        pg.LimitSurface(pg.Shape.disk(0.05), -1.0, 0.5)
    points = pg.LimitSurface(pg.Shape.box(0.1, 0.1), 1.0, 0.5, points=[[0.05, 0, 1.0], [-0.05, 0, 1.0]])
    assert points.summary["c"] == pytest.approx(0.05, rel=1e-12)
