"""The trimmed Kirchhoff–Love shell on NURBS whose weights are not a product
(``net_weights``, :mod:`splinedeform.trim.shell_trimmed`).

* A flat unit square with the weights of ``W = 1 + c u v`` (rank 2, not a product) and its
  control points placed so that ``x(u, v) = (u, v, 0)`` exactly: a clamped and a pinned
  disc under pressure against Kirchhoff's closed forms. On quintics the deflection (a
  quartic) times ``W`` (bilinear) is a polynomial of the B-splines, so the rational space
  holds it and the answer is round-off.
* Product weights given per control point against the same weights as two 1-D rational
  bases, on a curved net trimmed by a disc and by a rectangle less a hole: the same space
  through two evaluations (the quotient rule on the 2-D grid, the tensor of 1-D rational
  values), to round-off.
* The exact sphere octant reweighted without moving it (``tests/test_shell_weights.py``):
  trimmed by its own rectangle, its matrices are the untrimmed shell's; with a clamped hole
  it converges to the product-weight octant.
* A shell body whose trimmed faces have general weights: the split square (disc and the
  square less it, coupled along the circle) against the clamped square, and a body of CAD
  faces keeping the trim of such a face without a warning.
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.knots import KnotVectorBasis, RationalBasis
from splinedeform.physics.shell import ShellMaterial, matrices
from splinedeform.physics.shell_model import ShellModel
from splinedeform.refine import refine_surface
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain
from splinedeform.trim.shell_trimmed import trimmed_shell
from splinedeform.trim.values import tensor_values

from coupling_systems import CLAMPED_PLATE_CENTRE
from test_shell_weights import rational_octant, reweighted

A, E, NU, THICKNESS, Q = 0.4, 1.0e4, 0.3, 0.01, 1.0
D = E * THICKNESS ** 3 / (12 * (1 - NU ** 2))
MATERIAL = ShellMaterial(E, NU, THICKNESS, 1.0)
CLOSED_FORMS = {"clamped": Q * A ** 4 / (64 * D),                       # Timoshenko §62
                "pinned": (5 + NU) * Q * A ** 4 / (64 * (1 + NU) * D)}   # §63
SQUARE = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def relative(A, B) -> float:
    A, B = (np.asarray(X.toarray() if hasattr(X, "toarray") else X) for X in (A, B))
    return float(np.abs(A - B).max() / np.abs(A).max())


def weighted_plane(cells: int, degree: int, c: float) -> sd.Surface:
    """The unit square ``x = (u, v, 0)`` on open knots with the weights of ``W = 1 + c u v``.

    ``W``, ``W u`` and ``W v`` are polynomials of degree <= 2 in each variable, so their
    coefficients on the B-splines are exact: found by least squares on a grid of points
    (the residual is round-off); the control points are ``(W x)_kl / w_kl``."""
    plane = sd.shapes.plane(cells=(cells, cells), degree=degree, knots="open")
    bu, bv = plane.basis_u, plane.basis_v
    g = np.linspace(0.0, 1.0, 3 * cells + 4)
    U, V = (x.ravel() for x in np.meshgrid(g, g, indexing="ij"))
    B = tensor_values((bu, bv), np.stack([U, V], 1), [(0, 0)])[(0, 0)].toarray()
    W = 1.0 + c * U * V
    hom = np.linalg.lstsq(B, np.stack([W * U, W * V, W], 1), rcond=None)[0]
    P = np.zeros(plane.shape + (3,))
    P[..., :2] = (hom[:, :2] / hom[:, 2:]).reshape(plane.shape + (2,))
    return sd.Surface(P, bu, bv, net_weights=hom[:, 2].reshape(plane.shape))


def test_the_weighted_plane_is_the_plane():
    surface = weighted_plane(8, 5, 0.8)
    assert sd.rational.product_factors(surface.net_weights) is None    # genuinely general
    u = np.linspace(0.0, 1.0, 13)
    U, V = np.meshgrid(u, u, indexing="ij")
    X = surface.evaluate_grid(u, u)
    # the identity to round-off of the least squares and the quotient (measured 7e-15);
    # 1e-12
    assert np.abs(X[..., 0] - U).max() < 1e-12 and np.abs(X[..., 1] - V).max() < 1e-12
    assert np.abs(X[..., 2]).max() == 0.0                    # every control point has z = 0


@pytest.mark.parametrize("edge", ["clamped", "pinned"])
def test_a_disc_on_general_weights_is_kirchhoffs(edge):
    # the deflection is a quartic in (u, v), times W a polynomial of degree 5 in each
    # variable: in the rational space of the quintics, and Höllig's extension (through the
    # numerator's coefficients) reproduces it; Nitsche's terms are consistent, so the
    # centre is round-off (measured 7e-13 clamped, 2e-14 pinned, of the closed form on
    # 8 × 8 cells): 1e-9. The
    # in-plane displacement is zero (1e-12 of the deflection)
    surface = weighted_plane(8, 5, 0.8).with_trim(TrimDomain(CircleLoop((0.5, 0.5), A)))
    d = ShellModel(surface, MATERIAL, {"outer": edge}).static(sd.Pressure(Q)).displacement(
        0.5, 0.5)
    assert abs(d[2] / CLOSED_FORMS[edge] - 1) < 1e-9
    assert np.abs(d[:2]).max() < 1e-12 * d[2]


def test_a_free_disc_on_general_weights_keeps_its_six_rigid_motions():
    # the rigid motions are W-weighted polynomials of degree <= 2 here (W, W x): the
    # extension reproduces them, so all six are in range T
    surface = weighted_plane(6, 3, 0.8).with_trim(TrimDomain(CircleLoop((0.5, 0.5), A)))
    assert trimmed_shell(surface, MATERIAL, "free").motions.count == 6


def curved_pair() -> tuple[sd.Surface, sd.Surface]:
    """A curved cubic net on general knots with weights ``a bᵀ``: as two 1-D rational bases,
    and per control point."""
    bu = KnotVectorBasis(3, [0, 0, 0, 0, 0.2, 0.45, 0.7, 1, 1, 1, 1])
    bv = KnotVectorBasis(3, [0, 0, 0, 0, 0.3, 0.5, 0.8, 1, 1, 1, 1])
    X, Y = np.meshgrid(bu.greville(), bv.greville(), indexing="ij")
    net = np.stack([X, Y, 0.2 * np.sin(2 * X + Y)], axis=-1)
    rng = np.random.default_rng(1)
    a, b = rng.uniform(0.7, 1.4, bu.size), rng.uniform(0.7, 1.4, bv.size)
    return (sd.Surface(net, RationalBasis(bu, a), RationalBasis(bv, b)),
            sd.Surface(net, bu, bv, net_weights=np.outer(a, b)))


@pytest.mark.parametrize("domain, boundary, point", [
    (TrimDomain(CircleLoop((0.5, 0.5), 0.4)), {"outer": "clamped"}, (0.37, 0.61)),
    (TrimDomain(SQUARE, (CircleLoop((0.45, 0.55), 0.2),)),
     {"u0": "clamped", "v1": "pinned", "hole1": "clamped"}, (0.8, 0.3)),
])
def test_product_weights_per_point_are_the_rational_bases(domain, boundary, point):
    # the same rational space two ways, at the same trimmed points: K, M (measured 6e-16)
    # and T agree to round-off, held to 1e-12; static answers and frequencies to 1e-10
    # (measured 8e-14 and 2e-12: the solve and the eigensolver amplify round-off by the
    # condition of K_r)
    product, general = curved_pair()
    one, two = (trimmed_shell(s.with_trim(domain), MATERIAL, boundary)
                for s in (product, general))
    for X, Y in ((one.stiffness, two.stiffness), (one.mass, two.mass), (one.T, two.T)):
        assert relative(X, Y) <= 1e-12
    models = [ShellModel(s.with_trim(domain), MATERIAL, boundary) for s in (product, general)]
    for load in (sd.Pressure(Q), sd.Point(*point, [0.3, -0.2, 1.0])):
        assert relative(*(m.static(load).d_free for m in models)) <= 1e-10
    assert relative(*(m.frequencies(4) for m in models)) <= 1e-10
    free = [trimmed_shell(s.with_trim(domain), MATERIAL, "free").motions.count
            for s in (product, general)]
    assert free[0] == free[1]


SPHERE = ShellMaterial(1.0e6, 0.3, 2e-2)


def test_the_reweighted_octant_trimmed_by_its_rectangle_is_the_untrimmed_shell():
    # a trim that cuts nothing (the rectangle, edges free): the trimmed region's Gauss rule
    # is the untrimmed shell's (n + 2 points per cell), so K and M of the two assemblies
    # (the trimmed energy form at scattered points, the untrimmed cell by cell through the
    # metric's grid) agree to round-off: measured 2e-14 and 6e-16, held to 1e-12. Free, the
    # octant keeps its six rigid motions
    octant = refine_surface(reweighted(rational_octant()), insert=(3, 3))
    assert sd.rational.product_factors(octant.net_weights) is None
    trimmed = trimmed_shell(octant.with_trim(TrimDomain(SQUARE)), SPHERE, "free")
    K, M = matrices(octant, SPHERE)
    assert relative(K, trimmed.stiffness) <= 1e-12 and relative(M, trimmed.mass) <= 1e-12
    assert trimmed.motions.count == 6


def test_the_reweighted_octant_with_a_clamped_hole_meets_the_product_octant():
    # the same surface on two rational spaces (bicubic over g W, and the product octant
    # raised to bicubic over W), a hole clamped by Nitsche's terms and the edge u0 clamped
    # on the rectangle: the two answers approach each other as the spans are refined,
    # measured 3.7e-3 and 4.1e-4 of the largest displacement on 8 and 16 spans (a factor
    # 9); bounds with a factor 2 and a factor 4 between them
    domain = TrimDomain(SQUARE, (CircleLoop((0.45, 0.45), 0.2),))
    U, V = np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 0.9, 11), indexing="ij")
    keep = np.hypot(U - 0.45, V - 0.45) > 0.22
    gaps = []
    for spans in (8, 16):
        pair = (refine_surface(reweighted(rational_octant()), insert=(spans - 1,) * 2),
                refine_surface(rational_octant(), elevate=(1, 1), insert=(spans - 1,) * 2))
        d = [ShellModel(s.with_trim(domain), SPHERE, {"hole1": "clamped", "u0": "clamped"})
             .static(sd.Pressure(1.0)).displacement(U[keep], V[keep]) for s in pair]
        gaps.append(np.abs(d[0] - d[1]).max() / np.abs(d[1]).max())
    assert gaps[0] < 8e-3 and gaps[1] < 1e-3 and gaps[1] < gaps[0] / 4


def test_a_shell_body_of_faces_with_general_weights_is_the_clamped_square():
    # the split square (the disc and the square less it, coupled along the circle, clamped
    # on the square's edges by Nitsche's terms) with both faces on general weights, against
    # the same body on polynomial faces: measured 5.3e-6 of the largest deflection (the
    # discretisation error of either, 12 × 12 quartic cells), held to 5e-5; its centre to
    # Kirchhoff's 0.00126532 q a⁴ / D (measured 1.2e-5) within 1e-4
    from test_shell_body_trimmed import CIRCLE, SHELL, split_square

    shell_d = SHELL.E * SHELL.thickness ** 3 / (12 * (1 - SHELL.nu ** 2))
    weighted = sd.Body([weighted_plane(12, 4, 0.8).with_trim(TrimDomain(CIRCLE)),
                        weighted_plane(12, 4, -0.5).with_trim(TrimDomain(SQUARE, (CIRCLE,)))])
    assert all(p.net_weights is not None for p in weighted.patches)
    grid = np.linspace(0.02, 0.98, 25)
    U, V = (x.ravel() for x in np.meshgrid(grid, grid))
    inside = np.hypot(U - 0.5, V - 0.5) < 0.3
    w = []
    for body in (split_square(12, 12), weighted):
        model = ShellModel(body, SHELL, "clamped")
        assert model.rigid.shape[1] == 0
        static = model.static(sd.Pressure(1.0))
        w.append(np.concatenate([static.displacement(U[inside], V[inside], patch=0),
                                 static.displacement(U[~inside], V[~inside], patch=1)]))
    assert np.abs(w[1] - w[0]).max() < 5e-5 * np.abs(w[0]).max()
    centre = static.displacement(0.5, 0.5, patch=0)[2]
    assert abs(centre * shell_d / CLAMPED_PLATE_CENTRE - 1) < 1e-4


def test_a_shell_body_of_cad_faces_keeps_the_trim_of_a_face_with_general_weights(
        monkeypatch):
    # the body path of a scenario (scenario/cad_trim.py): a face with general weights is
    # trimmed under the shell as under every physics, with no warning
    from splinedeform import cad_trims
    from splinedeform.scenario.body import FileBody
    from splinedeform.scenario.cad_trim import with_body_trims

    faces = [weighted_plane(6, 3, 0.8), sd.shapes.plane(cells=(6, 6), degree=3, knots="open")]
    body = FileBody(faces, [], faces=[0, 1], counts={})
    loops = {0: TrimDomain(CircleLoop((0.5, 0.5), 0.3)),
             1: TrimDomain(SQUARE, (CircleLoop((0.5, 0.5), 0.3),))}
    monkeypatch.setattr(cad_trims, "read_trims", lambda path, face: loops[face])
    scenario = SimpleNamespace(surface=SimpleNamespace(path="two.step", parameters={}),
                               material=SimpleNamespace(physics="shell"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")                      # no face is taken whole
        trimmed = with_body_trims(scenario, body, [])
    assert all(p.trim is not None for p in trimmed.patches)
    assert trimmed.patches[0].net_weights is not None
    model = ShellModel(trimmed, MATERIAL, "clamped")
    assert np.isfinite(model.static(sd.Pressure(Q)).displacement(0.5, 0.5, patch=0)).all()
