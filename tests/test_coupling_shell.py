"""Coupling of Kirchhoff–Love shell patches: the vector forms on interleaved unknowns.

A fold keeps its angle (rigid motions cost nothing, a hinge motion its rotation squared),
and a clamped square plate split into two non-conforming shell patches bends like one
fine shell patch and like Kirchhoff's plate, ``w = 0.00126532 q a⁴ / D``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from splinedeform.basis import BSplineBasis
from splinedeform.body import Interface
from splinedeform.knots import KnotVectorBasis
from splinedeform.physics import coupling
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel
from splinedeform.surface import Surface

from coupling_systems import CLAMPED_PLATE_CENTRE, flat_patch, load_vector, offsets, uniform

SPLIT = Interface(0, "u1", 1, "u0", conforming=False)
SHELL = ShellMaterial(E=1.0, nu=0.3, thickness=0.01)
D = SHELL.E * SHELL.thickness ** 3 / (12 * (1 - SHELL.nu ** 2))


def folded() -> list[Surface]:
    """``[0, 1/2] × [0, 1]`` flat, and a wall standing on its edge x = 1/2 (90°, degree 2)."""
    floor = flat_patch(0.0, 0.5, 3, 4, degree=2)
    wall = flat_patch(0.0, 0.5, 2, 3, degree=2)
    P = wall.control_points
    standing = np.stack([0.5 + 0 * P[..., 0], P[..., 1], P[..., 0]], axis=-1)
    return [floor, wall.with_control_points(standing)]


def rigid(points: np.ndarray, omega, shift) -> np.ndarray:
    """Control displacements ``t + ω × (p − c)`` (exact: the motion is linear in ``x``)."""
    return (np.asarray(shift) + np.cross(omega, points - np.array([0.5, 0.0, 0.0]))).ravel()


def test_a_fold_keeps_its_angle_and_a_hinge_motion_pays_its_rotation():
    patches = folded()
    o = offsets(patches)
    R = coupling.shell_rotation_penalty(patches, SPLIT, 1.0, o)
    P = coupling.shell_displacement_penalty(patches, SPLIT, 1.0, o)
    scale = abs(R).sum() + abs(P).sum()
    for omega, shift in (([0.3, -0.2, 0.5], [1.0, 2.0, -1.0]), ([0.0, 1.0, 0.0], [0, 0, 0])):
        d = np.concatenate([rigid(p.control_points, omega, shift) for p in patches])
        # a rigid motion turns both sides alike: nothing to pay, to round-off (1e-12)
        assert abs(d @ R @ d) <= 1e-12 * scale * np.dot(d, d)
        assert abs(d @ P @ d) <= 1e-12 * scale * np.dot(d, d)
    # the wall turned by φ about the fold line, the floor still: no gap, a rotation φ
    # along the whole fold (length 1): ½ β φ² · 1, exact quadrature (1e-12)
    phi = 1e-3
    d = np.concatenate([0 * patches[0].control_points.ravel(),
                        rigid(patches[1].control_points, [0.0, phi, 0.0], [0, 0, 0])])
    assert 0.5 * d @ R @ d == pytest.approx(0.5 * phi ** 2, rel=1e-12)
    assert abs(d @ P @ d) <= 1e-12 * scale * np.dot(d, d)


def test_a_folded_c0_line_keeps_its_crease():
    # one degree-2 patch, u = 1/2 repeated twice, its net bent by 90° there
    basis = KnotVectorBasis(2, [0, 0, 0, 0.25, 0.5, 0.5, 0.75, 1, 1, 1])
    flat = flat_patch(0.0, 1.0, basis.cells, 3, degree=2, basis_u=basis)
    P = flat.control_points
    x = P[..., 0]
    bent = np.stack([np.minimum(x, 0.5), P[..., 1], np.maximum(x - 0.5, 0.0)], axis=-1)
    surface = flat.with_control_points(bent)
    (line,) = coupling.c0_lines(surface)
    R = coupling.shell_c0_rotation_penalty(surface, *line, 1.0)
    d = rigid(bent, [0.3, -0.2, 0.5], [1.0, 2.0, -1.0])
    assert abs(d @ R @ d) <= 1e-12 * abs(R).sum() * np.dot(d, d)    # round-off
    phi = 1e-3                                        # the upper side turned about the crease
    above = (x > 0.5)[..., None]
    d = np.where(above, rigid(bent, [0.0, phi, 0.0], [0, 0, 0]).reshape(bent.shape), 0.0)
    assert 0.5 * d.ravel() @ R @ d.ravel() == pytest.approx(0.5 * phi ** 2, rel=1e-12)


def shell_deflections(patches, starts, boundaries, coupling_matrix, points) -> list[float]:
    """Static deflections ``w D / (q a⁴)`` under a unit pressure (z) at ``(patch, u, v)`` points."""
    models = [ShellModel(s, SHELL, b) for s, b in zip(patches, boundaries)]
    K = sp.block_diag([m.K_full for m in models]).tocsr() + coupling_matrix
    T = sp.block_diag([m.T for m in models]).tocsr()
    F = np.zeros(K.shape[0])
    F[2::3] = np.concatenate([load_vector(s, x0, uniform) for s, x0 in zip(patches, starts)])
    d = T @ spla.spsolve((T.T @ K @ T).tocsc(), T.T @ F)
    parts = np.split(d.reshape(-1, 3)[:, 2], offsets(patches)[1:])
    return [D * float((patches[i].evaluation_matrix(u, v) @ parts[i])[0]) for i, u, v in points]


def single_shell(cells: int) -> float:
    clamped = {e: "clamped" for e in ("u0", "u1", "v0", "v1")}
    return shell_deflections([flat_patch(0.0, 1.0, cells, cells)], [0.0], [clamped], 0.0,
                             [(0, 0.5, 0.5)])[0]


def test_split_shell_plate_bends_like_one_shell_and_like_a_hinge_without_the_rotation():
    reference = single_shell(32)
    # the fine shell against Kirchhoff's plate (thin: t = a/100), within the 5 digits, 4e-5
    assert reference == pytest.approx(CLAMPED_PLATE_CENTRE, rel=4e-5)
    error = abs(single_shell(8) - reference)          # the coarser side's spans: 1.4e-4
    patches = [flat_patch(0.0, 0.5, 6, 12), flat_patch(0.5, 0.5, 4, 8)]
    bounds = [{"u0": "clamped", "v0": "clamped", "v1": "clamped"},
              {"u1": "clamped", "v0": "clamped", "v1": "clamped"}]
    o = offsets(patches)
    K = coupling.interface_penalty(patches, SPLIT, SHELL, o, ends=("clamped", "clamped"))
    centre = [(0, 0.5, 0.5), (1, 0.0, 0.5)]               # from either side
    w_left, w_right = shell_deflections(patches, [0.0, 0.5], bounds, K, centre)
    assert abs(w_left - reference) <= error
    assert abs(w_right - w_left) <= error
    alpha = coupling.penalty_factors(SHELL, coupling.interface_size(patches, SPLIT))[0]
    hinge = coupling.shell_displacement_penalty(patches, SPLIT, alpha, o, (2, 2))
    w_hinge = shell_deflections(patches, [0.0, 0.5], bounds, hinge, centre)[0]
    assert w_hinge / reference > 1.1
