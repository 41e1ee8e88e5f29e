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
    with pytest.raises(ValueError, match=r"twists\[0, 0\] is nan"):
        ls.sustaining_load([[np.nan, 0, 0]])
    with pytest.raises(pg.LimitSurfaceError, match="mass"):
        pg.LimitSurface(pg.Shape.disk(0.05), -1.0, 0.5)
    points = pg.LimitSurface(pg.Shape.box(0.1, 0.1), 1.0, 0.5, points=[[0.05, 0, 1.0], [-0.05, 0, 1.0]])
    assert points.summary["c"] == pytest.approx(0.05, rel=1e-12)
    # A load whose inverse solve stops short on a point support's non-smooth surface is said (C++'s
    # InverseResult::converged; Python returned it silently).
    legs = pg.LimitSurface(pg.Shape.box(1, 1), 1, 0.5, points=[[0, 0, 1], [1, 0, 1], [0, 1, 1]])
    with pytest.warns(UserWarning, match=r"twist_for_load: 1 of 1 loads did not converge \(the first: loads\[0\]"):
        legs.twist_for_load([[1.4675926467316445, 0.2993293920542826, 1.7320450791519741]])


def test_twist_for_load_columns_and_any_magnitude():
    # twist_for_load returns (vx, vy, omega) with |(vx, vy, c omega)| = 1 (docs/python.md); only a
    # direction matters, so loads and twists of 1e-300 to 1e300 give the same answers (the
    # ellipsoid maps returned zeros from about 1e154 on; the inverse called 1e155 "twist is zero").
    ls = pg.LimitSurface(pg.Shape.box(0.1, 0.1), 1.0, 0.3)
    c = ls.summary["c"]
    back = ls.twist_for_load([[1.0, 1.0, 1.0]])[0]
    assert math.hypot(back[0], back[1], c * back[2]) == pytest.approx(1.0, abs=1e-14)
    twist = np.array([1.0, 0.0, 1.0])
    load = np.array([0.7, -0.2, 0.004])
    at_one = (ls.ellipsoid_load([twist])[0], ls.ellipsoid_twist([load])[0], ls.twist_for_load([load])[0])
    for scale in (1e-300, 1e-160, 1e154, 1e300):
        np.testing.assert_allclose(ls.ellipsoid_load([scale * twist])[0], at_one[0], rtol=1e-15)
        np.testing.assert_allclose(ls.ellipsoid_twist([scale * load])[0], at_one[1], atol=1e-15)
        np.testing.assert_allclose(ls.twist_for_load([scale * load])[0], at_one[2], atol=1e-9)


def test_booleans_are_not_numbers():
    # A float argument given True was read as 1.0 (a 1 m disk, mu = 1) without a word.
    box = pg.Shape.box(0.1, 0.1)
    for call in (lambda: pg.Shape.disk(True), lambda: pg.LimitSurface(box, 1.0, True),
                 lambda: pg.LimitSurface(box, np.bool_(True), 0.3), lambda: pg.Shape.box(True, 1.0),
                 lambda: pg.Shape.disk(np.array(True))):
        with pytest.raises(TypeError):
            call()
    # Ints and NumPy scalars still convert.
    assert pg.LimitSurface(box, 1, np.float32(0.5)).summary["f_max"] == pytest.approx(0.5 * 9.80665, rel=1e-7)
    assert pg.Shape.disk(np.int64(2)).radius == 2.0
