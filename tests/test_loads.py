"""Generalised forces of the loads and their time profiles."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import splinedeform as sd
from splinedeform.errors import InputError


@settings(max_examples=30, deadline=None)
@given(u=st.floats(0, 2), v=st.floats(0, 1), knots=st.sampled_from(["open", "uniform"]))
def test_point_load_distributes_the_force_by_the_basis(u, v, knots):
    surf = sd.shapes.plane(size=(2.0, 1.0), cells=(5, 4), knots=knots)
    P = np.array([0.3, -1.0, 2.0])
    F = sd.Point(u, v, P).field_vector(surf)
    assert np.allclose(F.sum(axis=0), P)                  # partition of unity
    # the force's moment about the origin is reproduced through linear precision of x(u,v)
    assert np.allclose(F.T @ surf.control_points.reshape(-1, 3)[:, :2],
                       np.outer(P, surf.evaluate(u, v)[:2]))


def test_uniform_pressure_and_function_totals():
    surf = sd.shapes.plane(size=(2.0, 1.5), cells=(4, 3))
    area = 3.0
    F = sd.Uniform((0, 0, -2.0)).field_vector(surf)
    assert np.allclose(F.sum(axis=0), [0, 0, -2.0 * area])
    Fp = sd.Pressure(0.5).field_vector(surf)
    assert np.allclose(Fp.sum(axis=0), [0, 0, 0.5 * area])   # x_u × x_v = +z for this plane
    Ff = sd.Function(lambda u, v, t: np.stack([0 * u, 0 * u, 0 * u - 2.0], -1)).field_vector(surf)
    assert np.allclose(Ff, F)
    # a polynomial field is integrated exactly: ∫∫ u² v b_k b_l against a fine quadrature
    Fq = sd.Function(lambda u, v, t: np.stack([u**2 * v, 0 * u, 0 * u], -1)).field_vector(surf)
    assert Fq[:, 0].sum() == pytest.approx((2.0**3 / 3) * (1.5**2 / 2), rel=1e-12)


def test_pressure_on_a_half_sphere_equals_pressure_times_projected_area():
    R, q = 1.3, 0.7
    surf = sd.shapes.half_sphere(radius=R, cells=(12, 8))
    total = sd.Pressure(q).field_vector(surf).sum(axis=0)
    # |∫ q n dA| over a hemisphere is q π R² along its axis (up to the fit error)
    assert np.linalg.norm(total) == pytest.approx(q * np.pi * R**2, rel=1e-3)
    assert np.linalg.norm(total[:2]) < 1e-3 * np.linalg.norm(total)


def test_loads_add_and_scale_by_profiles():
    surf = sd.shapes.plane(cells=(3, 3))
    a = sd.Point(0.5, 0.5, (0, 0, 1), profile=sd.Step(1.0, 2.0))
    b = sd.Uniform((1, 0, 0), profile=sd.Harmonic(2.0, 0.5))
    total = a + b
    for t in (0.5, 1.0, 1.5, 2.0):
        expected = a.profile(t) * a.field_vector(surf) + np.sin(2 * t + 0.5) * b.field_vector(surf)
        assert np.allclose(total.vector(surf, t), expected)
    assert total.breakpoints() == [0.0, 1.0, 2.0]


def test_piecewise_jumps_rebuild_the_profile():
    p = sd.Piecewise([(0.5, 2.0), (1.0, -1.0), (3.0, 0.5)])
    t = np.linspace(0, 4, 81)
    rebuilt = sum(ds * (t >= tj) for tj, ds in p.jumps())
    assert np.allclose(rebuilt, p(t))
    assert p(0.2) == 0 and p(0.5) == 2.0 and p(2.9) == -1.0 and p(10) == 0.5


@pytest.mark.parametrize("make, words", [
    (lambda: sd.Point(0.5, 0.5, (0, 1)), "three numbers"),
    (lambda: sd.Point(np.nan, 0.5, (0, 0, 1)), "finite"),
    (lambda: sd.Uniform((0, np.inf, 1)), "finite"),
    (lambda: sd.Step(2.0, 1.0), "t_on < t_off"),
    (lambda: sd.Piecewise([(1.0, 1.0), (0.5, 2.0)]), "increasing"),
    (lambda: sd.Harmonic(-1.0), "> 0"),
    (lambda: sd.Function(3.0), "callable"),
    (lambda: sd.Point(0.5, 0.5, (0, 0, 1), profile="step"), "profile"),
])
def test_bad_loads_are_rejected(make, words):
    with pytest.raises(InputError, match=words):
        make()


def test_point_outside_domain_names_the_parameter():
    surf = sd.shapes.plane(size=(2.0, 1.0), cells=(3, 3))
    with pytest.raises(InputError, match=r"v=1.5 is outside the parameter domain \[0, 1\]"):
        sd.Point(0.5, 1.5, (0, 0, 1)).field_vector(surf)
