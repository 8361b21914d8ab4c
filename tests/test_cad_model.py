"""Surfaces and models on general knot vectors and NURBS patches (splinedeform.cad)."""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.cad import NurbsPatch, patch_from_surface, refine, surface_from_patch
from splinedeform.errors import InputError
from splinedeform.knots import KnotVectorBasis, RationalBasis

S = np.sqrt(0.5)
PLATE = sd.Material(w10=1.0, w01=0.5, w20=0.1, w11=0.1, w02=0.2)


def quarter_cylinder() -> NurbsPatch:
    """Exact quarter of the unit cylinder, length 2: weights (1, √½, 1) around, 1 along."""
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 1.0], ring + [0, 0, 2.0]], axis=1)
    knots = np.array([0, 0, 0, 1, 1, 1.0])
    return NurbsPatch((2, 2), knots, knots, points, np.outer([1, S, 1], [1, 1, 1]))


def _close(a, b, tol):
    a, b = np.asarray(a), np.asarray(b)
    assert np.abs(a - b).max() <= tol * max(np.abs(b).max(), 1e-300)


@pytest.mark.parametrize("kind", ["open", "uniform"])
def test_general_knot_model_equals_fast_layout(kind):
    surf = sd.shapes.saddle(cells=(6, 5), degree=3, knots=kind)
    general = surface_from_patch(patch_from_surface(surf))
    assert isinstance(general.basis_u, KnotVectorBasis)
    load = sd.Uniform((0, 0, -1.0)) + sd.Point(0.3, 0.6, (0.2, 0, -1.0))
    fast, slow = (sd.Model(s, PLATE, boundary={"u0": "clamped", "v1": "pinned"})
                  for s in (surf, general))
    # same matrices by two evaluators (Höllig recurrence vs Cox–de Boor) and two Gauss
    # layouts, both exact: they differ by round-off, 1e-12 of the largest entry
    for A, B in zip(fast.matrices(), slow.matrices()):
        _close(A.toarray(), B.toarray(), 1e-12)
    _close(slow.static(load).control_points(), fast.static(load).control_points(), 1e-12)
    _close(slow.frequencies(6), fast.frequencies(6), 1e-12)


def test_periodic_surface_round_trips_through_its_unwrapped_patch():
    surf = sd.shapes.cylinder(cells=(8, 4))
    patch = patch_from_surface(surf)
    u, v = np.linspace(0, surf.basis_u.length, 41), np.linspace(0, surf.basis_v.length, 9)
    # same spline by two evaluators: round-off of O(1) coordinates
    _close(patch.evaluate(u, v), surf.evaluate_grid(u, v), 1e-13)
    _close(surface_from_patch(patch).evaluate_grid(u, v), surf.evaluate_grid(u, v), 1e-13)


def test_rational_patch_becomes_rational_surface_and_stays_circular():
    surf = surface_from_patch(quarter_cylinder())
    assert isinstance(surf.basis_u, RationalBasis) and isinstance(surf.basis_v, KnotVectorBasis)
    u, v = np.meshgrid(np.linspace(0, 1, 100), np.linspace(0, 1, 100), indexing="ij")
    p = surf.evaluate(u, v)
    # exact NURBS circle: round-off of a few operations on O(1) numbers
    assert np.abs(np.hypot(p[..., 0], p[..., 1]) - 1).max() <= 1e-12
    fine = surface_from_patch(refine(quarter_cylinder(), 5))
    assert np.abs(fine.evaluate(u, v) - p).max() <= 1e-13      # knot insertion keeps the surface


def test_patch_knots_are_shifted_to_start_at_zero():
    base = quarter_cylinder()
    moved = NurbsPatch(base.degrees, base.knots_u + 3.0, 2.0 * base.knots_v - 1.0,
                       base.points, base.weights)
    surf = surface_from_patch(moved)
    assert surf.domain == ((0.0, 1.0), (0.0, 2.0))
    _close(surf.evaluate(0.5, 1.0), surface_from_patch(base).evaluate(0.5, 0.5), 1e-14)


def test_weights_that_are_not_a_product_are_kept_per_control_point():
    """The patch's own formula (homogeneous sums) and the surface agree to 1e-14 of the
    size: two evaluations of one quotient (round-off)."""
    patch = quarter_cylinder()
    w = patch.weights.copy()
    w[1, 1] = 2.0
    odd = NurbsPatch(patch.degrees, patch.knots_u, patch.knots_v, patch.points, w)
    surf = surface_from_patch(odd, source="odd.3dm face 0")
    # the weights are copied, not computed: only a conversion could change them, and the
    # tolerance is one rounding of a double
    np.testing.assert_allclose(surf.net_weights, w, rtol=1e-15, atol=0)
    u, v = np.linspace(0, 1, 7), np.linspace(0, 1, 5)
    _close(surf.evaluate_grid(u, v), odd.evaluate(u, v), 1e-14)


def _centre_and_frequency(surf):
    model = sd.Model(surf, PLATE, boundary="clamped")
    return model.static(sd.Pressure(-1.0)).displacement(0.5, 0.5), model.frequencies(1)[0]


def test_rational_model_converges_to_the_polynomial_approximation():
    """Exact NURBS cylinder refined by knot insertion vs. polynomial fits of the same map.

    Both discretise the same clamped plate under pressure on the same cylinder; their
    centre displacements and lowest frequencies must approach each other at the
    discretisation rate (measured ≈ 2 for degree 2).
    """
    exact = surface_from_patch(quarter_cylinder())
    gaps = []
    for cells in (4, 8, 16):
        d_r, w_r = _centre_and_frequency(surface_from_patch(refine(quarter_cylinder(), cells)))
        poly = sd.shapes.from_function(exact.evaluate, cells=cells, degree=2, knots="open")
        d_p, w_p = _centre_and_frequency(poly)
        gaps.append([np.linalg.norm(d_r - d_p) / np.linalg.norm(d_p), abs(w_r - w_p) / w_p])
    gaps = np.array(gaps)
    rates = np.log2(gaps[:-1] / gaps[1:])
    assert np.all(rates[-1] >= 1.5), (gaps, rates)
    assert gaps[-1].max() <= 2e-3, gaps


def test_bending_on_a_c0_knot_vector_is_coupled():
    # two quarter arcs joined by a double knot: C0 in u at 0.5
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0], [-1, 0, 0]])
    points = np.stack([ring, ring + [0, 0, 1.0], ring + [0, 0, 2.0]], axis=1)
    patch = NurbsPatch((2, 2), np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1.0]),
                       np.array([0, 0, 0, 1, 1, 1.0]), points,
                       np.outer([1, S, 1, S, 1], [1, 1, 1]))
    surf = surface_from_patch(patch)
    assert surf.basis_u.continuity == 0 and surf.basis_v.continuity == 2
    model = sd.Model(surf, sd.Material(w10=1, w01=1, w20=1), boundary={"u0": "clamped"})
    net = model.static(sd.Uniform((0.0, 0.0, -1.0))).control_points() - surf.control_points
    v, x = np.linspace(0, 1, 21), np.linspace(0, 1, 41)
    jump = surf.derivative(0.5, v, 1, 0, net) - surf.derivative(0.5 - 1e-12, v, 1, 0, net)
    largest = np.abs(surf.derivative(x[:, None], x[None, :], 1, 0, net)).max()
    # the rotation penalty ties the slopes across u = 0.5 (the arcs meet G1 there, with the
    # same parametric speed): the jump against the largest slope is the penalty's error on
    # two spans a side, 5.4e-5 measured, held to 1e-4
    assert np.abs(jump).max() <= 1e-4 * largest
    sd.Model(surf, sd.Material(w10=1, w01=1, w02=1), boundary={"u0": "clamped"})   # v is C2
