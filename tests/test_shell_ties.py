"""Exact tangent ties of the Kirchhoff–Love shell across smooth C0 lines and interfaces.

Where the rest shape is smooth across a conforming line (a C0 knot line inside a patch, a
conforming interface), the shell's constraint map ties the slopes of its three displacement
components exactly (:mod:`splinedeform.physics.coupling_ties`), and the rotation penalty is
left to creases and non-conforming interfaces. Checked on the flat clamped square (Kirchhoff's
``w = 0.00126532 q a⁴ / D``) and on the Scordelis–Lo roof of two exact NURBS faces (0.3006163,
PENGoLINS). The penalty's answers are taken by leaving the ties out (``smooth_ties`` finding
none), the way a crease is coupled.
"""

from __future__ import annotations

from math import cos, pi, sin

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.knots import KnotVectorBasis, RationalBasis
from splinedeform.physics import coupling_ties, shell_body, shell_formulation
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import AreaForce, ShellModel
from splinedeform.refine import refine_surface

from coupling_systems import CLAMPED_PLATE_CENTRE, c0_basis, c1_basis, flat_patch, slope_jump

SHELL = ShellMaterial(E=1.0, nu=0.3, thickness=0.01)
D = SHELL.E * SHELL.thickness ** 3 / (12 * (1 - SHELL.nu ** 2))
CLAMPED = {e: "clamped" for e in ("u0", "u1", "v0", "v1")}
LOAD = sd.Uniform((0.0, 0.0, 1.0))
R, L, HALF = 25.0, 50.0, 40 * pi / 180           # the Scordelis–Lo roof (tests/test_shell_body.py)
ROOF = ShellMaterial(4.32e8, 0.0, 0.25)
WEIGHT = AreaForce(force=(0.0, 0.0, -90.0))
REFERENCE = 0.3006163


def no_ties(patches, interfaces, offsets) -> coupling_ties.Ties:
    """``smooth_ties`` finding no smooth line: every line keeps the rotation penalty."""
    return coupling_ties.Ties(sp.csr_matrix((0, int(offsets[-1]))), frozenset(), frozenset())


def condition(model: ShellModel) -> float:
    """``λ_max / λ_min`` of ``K_r`` beside the free rigid motions (dense, small models)."""
    eigenvalues = np.linalg.eigvalsh(model.matrices()[2].toarray())
    return float(eigenvalues[-1] / eigenvalues[model.rigid.shape[1]])


def test_a_shell_with_a_c0_line_is_tied_and_sags_like_the_smooth_shell(monkeypatch):
    # the case: a flat clamped square whose u = 1/2 is repeated 3 times sagged 1.553
    # times the closed form, with a slope jump of 0.0104 (a hinge); the penalty left 7.6e-6
    smooth = ShellModel(flat_patch(0.0, 1.0, 8, 8), SHELL, CLAMPED)
    surface = flat_patch(0.0, 1.0, 8, 8, basis_u=c0_basis(3, 8))
    kinked = ShellModel(surface, SHELL, CLAMPED)
    assert kinked.formulation.ties.lines == {(0, "u", 0.5)}
    w_smooth, w = (float(m.static(LOAD).displacement(0.5, 0.5)[2]) * D for m in (smooth, kinked))
    # the 8 × 8 shell is 1.4e-4 off the closed form, within the 0.1 % asked
    assert abs(w_smooth / CLAMPED_PLATE_CENTRE - 1) <= 2e-4
    assert abs(w / CLAMPED_PLATE_CENTRE - 1) <= 1e-3
    # the tied space is the 8 × 8 one with a double knot at u = 1/2; the answer is
    # symmetric about x = 1/2, so its second derivative is continuous there too and it is
    # the smooth shell's: round-off of systems of condition ~1e4 (measured 4.8e-15), held
    # to 1e-10, far inside the discretisation error 1.4e-4
    assert abs(w - w_smooth) <= 1e-10 * w_smooth
    net = kinked.static(LOAD).net_displacement()[..., 2:]
    # below 1e-9 of the largest slope (measured 4.5e-12: the 1e-12 step of slope_jump)
    assert slope_jump(surface, net) <= 1e-9
    tied = condition(kinked)
    monkeypatch.setattr(shell_formulation, "smooth_ties", no_ties)
    penalised = ShellModel(surface, SHELL, CLAMPED)
    assert penalised.formulation.ties.lines == frozenset()
    # measured 1.29e4 (the smooth C1 patch's own) against 2.86e7 with the rotation penalty
    assert tied < 1e-2 * condition(penalised)


def test_the_tied_line_is_the_c1_space_under_an_unsymmetric_load():
    # a point load off the centre line (x = 0.3) and oblique: the tied C0 patch, two tied
    # conforming halves and the patch whose u = 1/2 is a double knot (C1 there, nothing to
    # tie) are the same space and energy assembled three ways: round-off of systems of
    # condition ~1e4 (measured 1.5e-15), held to 1e-10 of the largest displacement
    push = (0.1, -0.2, 1.0)
    c1 = ShellModel(flat_patch(0.0, 1.0, 8, 8, basis_u=c1_basis(3, 8)), SHELL, CLAMPED)
    c0 = ShellModel(flat_patch(0.0, 1.0, 8, 8, basis_u=c0_basis(3, 8)), SHELL, CLAMPED)
    halves = ShellModel([flat_patch(0.0, 0.5, 4, 8), flat_patch(0.5, 0.5, 4, 8)], SHELL,
                        "clamped")
    assert halves.formulation.ties.interfaces == {0}
    assert c1.n_free == c0.n_free == halves.n_free
    x = np.linspace(0.0, 1.0, 21)
    X, Y = np.meshgrid(x, x, indexing="ij")
    reference = c1.static(sd.Point(0.3, 0.4, push)).displacement(X, Y)
    tied = c0.static(sd.Point(0.3, 0.4, push)).displacement(X, Y)
    on_halves = halves.static(sd.body.OnPatch(sd.Point(0.3, 0.4, push), patch=0))
    body = np.where((X <= 0.5)[..., None],
                    on_halves.displacement(np.minimum(X, 0.5), Y, patch=0),
                    on_halves.displacement(np.maximum(X - 0.5, 0.0), Y, patch=1))
    scale = np.abs(reference).max()
    assert np.abs(tied - reference).max() <= 1e-10 * scale
    assert np.abs(body - reference).max() <= 1e-10 * scale


def test_a_creased_shell_interface_keeps_its_rotation_penalty():
    # two flat halves folded by 90° along x = 1/2 (conforming): a tie would flatten the fold
    left = flat_patch(0.0, 0.5, 4, 4)
    P = flat_patch(0.5, 0.5, 4, 4).control_points.copy()
    P[..., 2], P[..., 0] = P[..., 0] - 0.5, 0.5
    folded = ShellModel([left, sd.Surface(P, left.basis_u, left.basis_v)], SHELL, "clamped")
    assert folded.formulation.ties.interfaces == frozenset()
    flat = ShellModel([left, flat_patch(0.5, 0.5, 4, 4)], SHELL, "clamped")
    assert flat.formulation.ties.interfaces == {0}


def roof_face(a0: float, a1: float, spans: int) -> sd.Surface:
    """The arc from angle ``a0`` to ``a1`` (from the crest, about the y axis) exactly, a
    rational quadratic (weights 1, cos h, 1) times a straight line in ``v = y``, elevated to
    cubic with ``spans`` spans across and ``2 spans`` along."""
    h, m = 0.5 * (a1 - a0), 0.5 * (a0 + a1)
    arc = [(R * sin(a0), R * cos(a0)), (R / cos(h) * sin(m), R / cos(h) * cos(m)),
           (R * sin(a1), R * cos(a1))]
    P = np.array([[[x, y, z] for y in (0.0, L / 2, L)] for x, z in arc])
    knots = np.array([0, 0, 0, 1, 1, 1.0])
    rest = sd.Surface(P, RationalBasis(KnotVectorBasis(2, knots), np.array([1, cos(h), 1])),
                      KnotVectorBasis(2, knots * L))
    return refine_surface(rest, (1, 1), (spans - 1, 2 * spans - 1))


def joined_roof(spans: int) -> sd.Surface:
    """The two faces of :func:`roof_face` as one patch: the arcs joined at ``u = 1``, a
    double knot of the quadratic (a C0 line inside the face, smooth across it), elevated
    and refined alike (``spans`` per arc)."""
    h = HALF / 2
    arc = [(R / (cos(h) if k % 2 else 1.0) * sin(angle), R / (cos(h) if k % 2 else 1.0)
            * cos(angle)) for k, angle in enumerate(np.linspace(-HALF, HALF, 5))]
    P = np.array([[[x, y, z] for y in (0.0, L / 2, L)] for x, z in arc])
    across = RationalBasis(KnotVectorBasis(2, [0, 0, 0, 1, 1, 2, 2, 2.0]),
                           np.array([1, cos(h), 1, cos(h), 1]))
    rest = sd.Surface(P, across, KnotVectorBasis(2, np.array([0, 0, 0, 1, 1, 1.0]) * L))
    return refine_surface(rest, (1, 1), (spans - 1, 2 * spans - 1))


def crest_slope_jump(solution, faces: list[sd.Surface]) -> float:
    """Jump of ``∂_u d / |a_u|`` across the crest (face 0's ``u1``, face 1's ``u0``) over
    its largest value on both faces."""
    nets = solution.net_displacement()
    v = np.linspace(0.0, L, 41)

    def slope(face: int, u) -> np.ndarray:
        s, U = faces[face], np.broadcast_to(u, np.broadcast_shapes(np.shape(u), v.shape))
        return (s.derivative(U, v, 1, 0, control_points=nets[face])
                / np.linalg.norm(s.derivative(U, v, 1, 0), axis=-1)[..., None])
    largest = max(np.abs(slope(f, np.linspace(0.0, 1.0, 21)[:, None])).max() for f in (0, 1))
    return float(np.abs(slope(0, 1.0) - slope(1, 0.0)).max() / largest)


def test_the_scordelis_lo_roof_of_two_exact_faces_is_tied(monkeypatch):
    faces = [roof_face(-HALF, 0.0, 4), roof_face(0.0, HALF, 4)]
    body = sd.Body(faces)
    assert body.summary()["shared"] == 1 and body.summary()["non_conforming"] == 0
    ends = {(p, e): "diaphragm" for p, e in body.topology.boundary if e[0] == "v"}
    one = ShellModel(joined_roof(4), ROOF, {"v0": "diaphragm", "v1": "diaphragm"})
    assert one.formulation.ties.lines == {(0, "u", 1.0)}
    w_joined = -one.static(WEIGHT).displacement(0.0, L / 2)[2]
    results = {}
    for tied in (True, False):
        if not tied:
            monkeypatch.setattr(shell_body, "smooth_ties", no_ties)
        model = ShellModel(body, ROOF, ends)
        assert model.formulation.ties.interfaces == ({0} if tied else frozenset())
        solution = model.static(WEIGHT)
        results[tied] = (-solution.displacement(0.0, L / 2, patch=0)[2],
                         crest_slope_jump(solution, faces), condition(model))
    (w, jump, kappa), (w_penalty, jump_penalty, kappa_penalty) = results[True], results[False]
    # measured 0.300075 at 4 × 8 cubic spans per face, 0.18 % low: the discretisation error
    assert w == pytest.approx(REFERENCE, rel=0.005)
    # the penalty's answer differs by 7.9e-6 of it, well inside that error (1.8e-3)
    assert abs(w_penalty - w) <= 0.1 * abs(w - REFERENCE)
    # the rotation across the crest: round-off with the tie (measured 5e-16), the
    # penalty's 4.5e-4 without it
    assert jump <= 1e-9 < 1e-6 < jump_penalty
    # condition numbers beside the axial translation the diaphragms leave free: measured
    # 1.3e5 tied against 4.5e7 with the penalty
    assert kappa < 1e-2 * kappa_penalty
    # the same roof as one face whose C0 line at the crest is tied: the same space and
    # energy as the tied body, another assembly: measured 5.9e-12 apart (round-off through
    # the condition 1.3e5), held to 1e-9
    assert w_joined == pytest.approx(w, rel=1e-9)
