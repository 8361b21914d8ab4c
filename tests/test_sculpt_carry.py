"""A re-solve carries the motion: the old modal state projected onto the new modes."""
from __future__ import annotations

import numpy as np
import pytest

from splinedeform.scenario import build, parse_scenario
from splinedeform.sculpt.carry import carried_fraction, carry
from splinedeform.sculpt.modal import sculpt_basis
from splinedeform.sculpt.state import advance

SHEET = """\
[surface]
shape = "plane"
cells = 4
[material]
mass = 1.0
damping = 0.3
w10 = 1.0
w01 = 1.0
w20 = 0.01
w02 = 0.01
[boundary]
u0 = "clamped"
u1 = "pinned"
[solve]
kind = "modes"
"""


def basis_of(text: str, modes: int | None = None):
    return sculpt_basis(build(parse_scenario(text, source="sheet.toml")).model, 9, modes)


def moving_state(basis, tau: float = 0.7):
    """``(q, q')`` some time after a push at a grid point was switched on from rest."""
    f = basis.participation(0.6, 0.3)[:, None] * np.array([0.1, -0.2, 1.0])[None, :]
    k = basis.lam.size
    return advance(basis.lam, basis.damping, np.zeros((k, 3)), np.zeros((k, 3)), f, tau)


def test_same_free_set_all_modes_the_motion_is_continuous_and_continues_as_model_dynamic():
    old = basis_of(SHEET)
    stiffer = SHEET.replace("w10 = 1.0", "w10 = 3.0").replace("mass = 1.0", "mass = 1.7")
    new = basis_of(stiffer)
    q, v = moving_state(old)
    q2, v2 = carry(old, new, q, v)
    d_old, d_new = old.phi_net @ q, new.phi_net @ q2
    # every mode kept, same free set: Φ Φᵀ M_r = I, so equal up to rounding of the eigensolve
    # (relative 1e-10 of the largest displacement, ~1e6 ulp of slack)
    scale = np.abs(d_old).max()
    assert scale > 1e-3
    np.testing.assert_allclose(d_new, d_old, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(new.phi_net @ v2, old.phi_net @ v, rtol=0,
                               atol=1e-10 * np.abs(old.phi_net @ v).max())
    assert carried_fraction(old, new, q) == pytest.approx(1.0, abs=1e-12)
    # and then it moves as Model.dynamic started from that displacement and velocity
    # (an independent path: least-squares restriction to the free coordinates, its own modes)
    model = new.model
    shape = model.surface.shape + (3,)
    tau = 0.45
    solution = model.dynamic(None, 1.0, initial_displacement=d_old.reshape(shape),
                             initial_velocity=(old.phi_net @ v).reshape(shape))
    expected = solution.control_points(tau) - model.surface.control_points
    zero = np.zeros_like(q2)
    q3 = advance(new.lam, new.damping, q2, v2, zero, tau)[0]
    np.testing.assert_allclose((new.phi_net @ q3).reshape(shape), expected, rtol=0,
                               atol=1e-9 * scale)


def test_a_shrinking_free_set_snaps_the_newly_fixed_points_to_rest():
    old = basis_of(SHEET)
    new = basis_of(SHEET.replace('u1 = "pinned"\n', 'u1 = "pinned"\n'
                                 "free_points = [[2, 2], [2, 3], [3, 2], [3, 3], [4, 3]]\n"))
    q, v = moving_state(old)
    q2, v2 = carry(old, new, q, v)
    shape = new.model.surface.shape
    d_new = (new.phi_net @ q2).reshape(shape + (3,))
    fixed = np.ones(shape, bool)
    fixed[[2, 2, 3, 3, 4], [2, 3, 2, 3, 3]] = False
    assert np.all(d_new[fixed] == 0.0)          # fixed points are no unknowns: exactly at rest
    assert np.abs(d_new[~fixed]).max() > 0
    kept = carried_fraction(old, new, q)
    assert 0.0 < kept < 1.0                     # the motion of the points now fixed is lost


def test_a_truncated_basis_keeps_at_most_the_whole_motion():
    old = basis_of(SHEET, 12)
    new = basis_of(SHEET.replace("w10 = 1.0", "w10 = 3.0"), 12)
    q, _ = moving_state(old)
    kept = carried_fraction(old, new, q)
    # the M-projection never adds: 0 < kept <= 1 (+ rounding)
    assert 0.5 < kept <= 1.0 + 1e-12
