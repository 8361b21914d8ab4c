"""The motion carried across a re-solve: the current state projected onto the new modes.

A re-solve (new material, boundary or free set) must not reset the motion. The page's state
is ``(q, q')`` in the old modes, i.e. the control net moves by ``d = T_old Φ_old q`` with
velocity ``T_old Φ_old q'``. Its projection onto the new modes in the new mass matrix ``M``
(unreduced, ``(n_u n_v)²``; ``Φ_newᵀ T_newᵀ M T_new Φ_new = I``) is

    q_new = P q,   q_new' = P q',   P = Φ_newᵀ T_newᵀ M T_old Φ_old     (k_new × k_old)

the best fit of the old displacement (and velocity) in the mass norm
``‖d‖²_M = dᵀ M d``. What is kept:

- the same free set and every mode kept: ``T_new Φ_new P = T_old Φ_old`` on the motion,
  the displacement is continuous to rounding (``Φ Φᵀ M_r = I`` for a complete basis);
- a truncated basis: the part of the motion outside the span of the new lowest modes is
  lost (after a material change the old lowest modes are not in the new ones' span);
- a free set that shrinks: the control points now fixed snap to rest, and the points
  still free take the mass-norm best fit (close to, not exactly, their old displacement
  near the newly fixed ones); a free set that grows loses nothing.

:func:`carried_fraction` measures what is kept, ``‖T_new Φ_new P q‖_M / ‖d‖_M``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .modal import SculptBasis

Array = NDArray[np.float64]


def transfer(old: SculptBasis, new: SculptBasis) -> Array:
    """``P = Φ_newᵀ T_newᵀ M T_old Φ_old`` with the new model's mass matrix, ``(k_new, k_old)``."""
    if [s.shape for s in old.patches] != [s.shape for s in new.patches]:
        raise ValueError("a state is carried only between models of the same control net")
    M = new.model.M_full
    return np.asarray(new.phi_net.T @ (M @ old.phi_net))


def carry(old: SculptBasis, new: SculptBasis, q: Array, v: Array) -> tuple[Array, Array]:
    """The state ``(q, q')`` of ``old`` (arrays ``(k_old, 3)``) in the modes of ``new``."""
    P = transfer(old, new)
    return P @ q, P @ v


def carried_fraction(old: SculptBasis, new: SculptBasis, q: Array) -> float:
    """``‖T_new Φ_new P q‖_M / ‖T_old Φ_old q‖_M`` (1: nothing lost; 1 for ``q = 0``)."""
    M = new.model.M_full
    d = old.phi_net @ q
    kept = new.phi_net @ (transfer(old, new) @ q)
    total = float(np.sum(d * (M @ d)))
    return 1.0 if total <= 0 else float(np.sqrt(max(np.sum(kept * (M @ kept)), 0.0) / total))
