"""Intrinsic physics: the energy measured on the surface does not depend on its parametrisation.

References are closed forms (Laplace–Beltrami spectrum of the unit sphere) and the same
surface computed under a second, non-affine parametrisation; the tolerances are the
discretisation errors measured on these nets (they fall by ~20× per refinement).
"""

from math import pi

import numpy as np
import pytest
from scipy.optimize import brentq

import splinedeform as sd
from splinedeform.errors import InputError
from splinedeform.physics import metric

PLATE = sd.Material(w10=1, w01=1, w20=0.01, w02=0.01)


def lonlat(u, v):
    return np.stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)], -1)


def plane_pair(cells):
    """The unit square, by its coordinates and by a non-affine map of the square onto itself."""
    a = sd.shapes.from_function(lambda u, v: np.stack([u, v, 0 * u], -1), cells=cells)
    b = sd.shapes.from_function(
        lambda u, v: np.stack([(u + u * u) / 2, v + 0.15 * u * np.sin(pi * v), 0 * u], -1),
        cells=cells)
    return a, b


def plane_inverse(X, Y):
    u = (-1 + np.sqrt(1 + 8 * X)) / 2
    v = np.array([brentq(lambda t: t + 0.15 * s * np.sin(pi * t) - y, 0, 1) for s, y in zip(u, Y)])
    return u, v


def relative_difference(physics, pair, inverse, points, cells, boundary):
    a, b = pair(cells)
    load = sd.loads.Pressure(1.0)
    da = sd.Model(a, PLATE, boundary=boundary, physics=physics).static(load).displacement(*points)
    db = sd.Model(b, PLATE, boundary=boundary, physics=physics).static(load).displacement(
        *inverse(*points))
    return float(np.abs(da - db).max() / np.abs(da).max())


def test_plane_reparametrised_converges_to_the_same_deformation():
    rng = np.random.default_rng(0)
    points = rng.uniform(0.05, 0.95, (2, 20))
    errors = [relative_difference("intrinsic", plane_pair, plane_inverse, points, c, "clamped")
              for c in (4, 8, 16)]
    # measured 0.12, 0.020, 0.0005: the difference is discretisation error, shrinking fast
    assert errors[2] < 2e-3
    assert errors[2] < errors[1] / 8 < errors[0] / 8
    # the paper's parametric energy keeps a parametrisation-dependent answer (measured 0.16)
    assert relative_difference("parametric", plane_pair, plane_inverse, points, 16,
                               "clamped") > 0.1


def phi2(u):
    return u + 0.3 * np.sin(u)


def theta2(s):
    return pi / 2 * (s + 0.4 * s * (1 - s))


def half_sphere_pair(cells):
    """Latitude–longitude, and a polar map with non-uniform longitude and latitude."""
    a = sd.shapes.from_function(lonlat, cells=cells, knots=("periodic", "open"),
                                domain=((0, 2 * pi), (0, pi / 2)))
    b = sd.shapes.from_function(lambda u, v: lonlat(phi2(u), theta2(v)), cells=cells,
                                knots=("periodic", "open"), domain=((0, 2 * pi), (0, 1)))
    return a, b


def half_sphere_inverse(P, T):
    return (np.array([brentq(lambda t: phi2(t) - p, 0, 2 * pi) for p in P]),
            np.array([brentq(lambda t: theta2(t) - q, 0, 1) for q in T]))


def test_half_sphere_two_polar_maps_agree_and_the_pole_stays_whole():
    rng = np.random.default_rng(1)
    points = np.stack([rng.uniform(0.1, 2 * pi - 0.1, 20), rng.uniform(0.1, pi / 2 - 0.02, 20)])
    errors = [relative_difference("intrinsic", half_sphere_pair, half_sphere_inverse, points, c,
                                  {"v0": "clamped"}) for c in ((8, 4), (16, 8))]
    # measured 0.034 and 0.0069 (0.0003 at 32×16)
    assert errors[1] < 0.01 and errors[1] < errors[0] / 3
    # the pole row of control points moves as one point (single-valued displacement):
    # spread measured 7e-8 against a deflection of 0.44; the parametric energy tears it (0.29)
    surface = half_sphere_pair((16, 8))[0]
    spreads = {}
    for physics in ("intrinsic", "parametric"):
        solution = sd.Model(surface, PLATE, boundary={"v0": "clamped"},
                            physics=physics).static(sd.loads.Pressure(1.0))
        d = solution.control_points() - surface.control_points
        spreads[physics] = float(np.ptp(d[:, -1], axis=0).max() / np.abs(d).max())
    assert spreads["intrinsic"] < 1e-5
    assert spreads["parametric"] > 0.1


def test_sphere_membrane_frequencies_are_laplace_beltrami_eigenvalues():
    sphere = sd.shapes.from_function(lonlat, cells=(16, 8), knots=("periodic", "open"),
                                     domain=((0, 2 * pi), (-pi / 2, pi / 2)))
    assert metric.poles(sphere) == ("v0", "v1")
    lam, _ = sd.Model(sphere, sd.Material(w10=1, w01=1), physics="intrinsic").eigen(16)
    expected = np.repeat([0, 2, 6, 12], [1, 3, 5, 7]).astype(float)
    # l(l+1) with multiplicity 2l+1; measured relative error <= 3e-4 at 16×8 cells
    np.testing.assert_allclose(lam[1:], expected[1:], rtol=1e-3)
    assert abs(lam[0]) < 1e-8   # the translation costs nothing (round-off scale)


def test_intrinsic_equals_parametric_on_an_arc_length_plane():
    # on a plane parametrised by its coordinates the metric is the identity. (Δd)² differs
    # from d_uu² + 2 d_uv² + d_vv² by 2(d_uu d_vv - d_uv²), a null Lagrangian whose integral
    # vanishes on clamped edges: the reduced matrices agree to round-off (1e-10 relative)
    plane = sd.shapes.plane(cells=(5, 4))
    mat = sd.Material(w10=2, w01=2, w20=0.5, w11=0.5, w02=0.5)
    Ki = sd.Model(plane, mat, boundary="clamped", physics="intrinsic").matrices()[2]
    Kp = sd.Model(plane, mat, boundary="clamped").matrices()[2]
    assert abs(Ki - Kp).max() < 1e-10 * abs(Kp).max()
    membrane = sd.Material(w10=2, w01=2)
    Ki = sd.Model(plane, membrane, physics="intrinsic").K_full
    Kp = sd.Model(plane, membrane).K_full
    assert abs(Ki - Kp).max() < 1e-10 * abs(Kp).max()


def test_degenerate_metric_inside_is_refused_with_the_point():
    folded = sd.shapes.from_function(
        lambda u, v: np.stack([(2 * u - 1) ** 3, v, 0 * u], -1), cells=4)
    with pytest.raises(InputError, match=r"degenerates at parameter \(u, v\) = \(0\.5, 0\)"):
        sd.Model(folded, PLATE, physics="intrinsic")


def test_anisotropic_weights_and_unknown_physics_are_refused():
    plane = sd.shapes.plane(cells=3)
    with pytest.raises(InputError, match="isotropic"):
        sd.Model(plane, sd.Material(w10=1, w01=2), physics="intrinsic")
    with pytest.raises(InputError, match="physics must be one of"):
        sd.Model(plane, PLATE, physics="membrane")


def test_scenario_selects_the_physics_and_names_a_bad_value():
    from splinedeform.errors import ScenarioError
    from splinedeform.scenario import build, parse_scenario

    text = """
[surface]
shape = "half_sphere"
cells = [8, 4]
[material]
w10 = 1.0
w01 = 1.0
physics = "{physics}"
[boundary]
v0 = "clamped"
[[load]]
kind = "pressure"
q = 1.0
[solve]
kind = "static"
"""
    model = build(parse_scenario(text.format(physics="intrinsic"))).model
    assert model.physics == "intrinsic"
    with pytest.raises(ScenarioError, match=r"case\.toml:8: material\.physics: expected one of"):
        parse_scenario(text.format(physics="membrane"), source="case.toml")
