"""Rigid modes of bodies at any size: the null space of the coupled stiffness.

A body that nothing holds and whose energy only bends has rigid modes that depend on its
geometry; they are found on the matrices, by dense ``eigh`` up to
:data:`~splinedeform.solvers.rigid.DENSE_NULL` free coordinates and by shift-invert Lanczos
near 0 beyond. The answers are known in closed form:

* the plate's energy ``∫ (Δ_S d)²`` (intrinsic) on a closed box vanishes on the constants
  only (a harmonic field on a closed surface is constant; the crease penalties hold the
  slopes across the edges): 1 per coordinate, the translations;
* the parametric plate ``d_uu² + 2 w11 d_uv² + d_vv²`` on a flat body: ``1, x, y`` (and
  ``xy`` without the twist);
* the Kirchhoff–Love shell on a free body: the 6 rigid motions, 3 translations and 3
  rotations;
* held on its rim, an open box has none: a harmonic field vanishing on the boundary is 0.
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.solvers import rigid

from body_patches import flat_patch

BENDING = sd.Material(w20=1.0, w11=1.0, w02=1.0)
SHELL = sd.ShellMaterial(1e4, 0.3, 0.01)


def box(cells: int, faces: int = 6) -> list[sd.Surface]:
    """The unit cube's first ``faces`` faces (the sixth, ``z = 1``, last), bicubic
    ``cells × cells`` each, their interfaces found where their edges meet."""
    P = flat_patch((0, 1), (0, 1), (cells, cells))
    X, Y = P.control_points[..., 0], P.control_points[..., 1]
    O, I = np.zeros_like(X), np.ones_like(X)
    nets = [(X, Y, O), (X, O, Y), (X, I, Y), (O, X, Y), (I, X, Y), (X, Y, I)]
    return [sd.Surface(np.stack(n, axis=-1), P.basis_u, P.basis_v) for n in nets[:faces]]


@pytest.fixture(scope="module")
def large_box() -> sd.Body:
    body = sd.Body(box(15))
    assert body.summary()["shared"] == 12 and body.summary()["boundary"] == 0
    return body


@pytest.mark.parametrize("physics", ["intrinsic", "parametric"])
def test_a_large_free_plate_box_has_the_translations_as_rigid_modes(large_box, physics):
    model = sd.BodyModel(large_box, BENDING, physics=physics)
    assert model.n_free > rigid.DENSE_NULL               # 1736: the Lanczos path
    assert model.rigid_modes == 1                        # a constant, per coordinate
    Z = model.rigid_fields
    field = np.concatenate([f.ravel() for f in model.to_full(Z[:, 0])])
    # the constant field at every control point: its spread is round-off of an
    # M-orthonormal vector of entries O(1) (measured 2e-13)
    assert np.ptp(field) <= 1e-10 * np.abs(field).max()
    M, _, K = model.matrices()
    # K_r annihilates it to round-off of K's largest entries (penalties of 1e5 D/h)
    assert np.abs(K @ Z).max() <= 1e-12 * abs(K).max()
    np.testing.assert_allclose(Z.T @ (M @ Z), [[1.0]], rtol=1e-12)   # M-orthonormal


def test_a_large_free_shell_box_has_six_rigid_motions(large_box):
    model = sd.ShellModel(large_box, SHELL)
    assert model.n_free > rigid.DENSE_NULL
    assert model.rigid_modes == 6
    words = " ".join(model.rigid_motions)
    assert words.count("translation") == 3 and words.count("rotation") == 3
    R = model.rigid
    M, _, K = model.matrices()
    # rigid motions cost no energy: ‖K R‖ at round-off of ‖K‖ (entries of R are O(1))
    assert np.abs(K @ R).max() <= 1e-10 * abs(K).max()


@pytest.mark.parametrize("rim", ["pinned", "clamped"])
def test_a_large_open_box_held_on_its_rim_has_no_rigid_mode(rim):
    body = sd.Body(box(16, faces=5))
    assert body.summary()["boundary"] == 4
    plate = sd.BodyModel(body, BENDING, boundary=rim)
    assert plate.n_free > rigid.DENSE_NULL
    assert plate.rigid_modes == 0
    # pinned: decided on the matrices (no eigenvalue at round-off, no translation admitted)
    if rim == "pinned":
        assert plate.rigid_fields.shape[1] == 0
    assert sd.ShellModel(body, SHELL, rim).rigid_modes == 0


@pytest.mark.parametrize("physics, twist, count", [
    ("parametric", 1.0, 3),          # 1, x, y
    ("parametric", 0.0, 4),          # and xy
])
def test_a_large_free_flat_body_has_the_fields_its_energy_leaves(physics, twist, count):
    left = flat_patch((0, 0.5), (0, 1), (20, 40))
    right = flat_patch((0.5, 1), (0, 1), (20, 40))
    model = sd.BodyModel(sd.Body([left, right]), sd.Material(w20=1.0, w11=twist, w02=1.0),
                         physics=physics)
    assert model.n_free > rigid.DENSE_NULL
    assert model.rigid_modes == count
    # the null fields are the polynomials named: fitted by 1, x, y (, xy) at the control
    # points of both patches to round-off (entries O(1); measured 1e-12)
    points = np.concatenate([s.control_points.reshape(-1, 3) for s in (left, right)])
    x, y = points[:, 0], points[:, 1]
    basis = np.column_stack([np.ones_like(x), x, y, x * y][:count])
    for column in model.rigid_fields.T:
        field = np.concatenate([f.ravel() for f in model.to_full(column)])
        coef, *_ = np.linalg.lstsq(basis, field, rcond=None)
        assert np.abs(basis @ coef - field).max() <= 1e-8 * np.abs(field).max()


@pytest.mark.parametrize("physics, twist, count", [
    ("intrinsic", 1.0, 8), ("parametric", 1.0, 3), ("parametric", 0.0, 4)])
def test_lanczos_and_dense_agree_on_the_null_space(monkeypatch, physics, twist, count):
    """The counts of tests/test_body_model.py (dense ``eigh``), by Lanczos: its blocks grow
    past the 8 harmonic fields of the intrinsic square."""
    halves = [flat_patch((0, 0.5), (0, 1), (3, 3)),
              flat_patch((0.5, 1), (0, 1), (3, 3), reverse_u=True)]
    material = sd.Material(w20=1.0, w11=twist, w02=1.0)
    dense = sd.BodyModel(halves, material, physics=physics)
    monkeypatch.setattr(rigid, "DENSE_NULL", 0)
    sparse = sd.BodyModel(halves, material, physics=physics)
    assert dense.rigid_modes == count
    assert sparse.rigid_modes == count
    # the same space: the projector of one onto the other is the identity to 1e-8 (the
    # Lanczos vectors converge to residuals of 1e-10 with gaps of O(1) in 1/(λ + σ))
    M = dense.matrices()[0]
    A, B = dense.rigid_fields, sparse.rigid_fields
    overlap = A.T @ (M @ B)
    np.testing.assert_allclose(overlap @ overlap.T, np.eye(count), atol=1e-8)
