"""What the solvers are given: the reduced system, its Kronecker factors, the reduction map.

The solvers see matrices, never a model. A model (:mod:`splinedeform.model`) gathers

* :class:`KroneckerFactors` — the reduced 1-D Gram matrices of a tensor-product model with
  per-edge constraints ``T = T_u ⊗ T_v`` and the consistent mass::

      M_r = μ Ĝ^u_0 ⊗ Ĝ^v_0,
      K_r = w10 Ĝ^u_1⊗Ĝ^v_0 + w01 Ĝ^u_0⊗Ĝ^v_1 + w20 Ĝ^u_2⊗Ĝ^v_0 + 2 w11 Ĝ^u_1⊗Ĝ^v_1
            + w02 Ĝ^u_0⊗Ĝ^v_2,          Ĝ^u_a = T_uᵀ G^u_a T_u,

  with, per direction, the dimension of the null space of the direction's stiffness (its
  rigid motions, decided from the constraints by :mod:`.rigid`);
* :class:`Reduction` — the constraint map ``d = T d_free`` and what a load needs to be
  reduced onto it (``F_r = Tᵀ F``, plus the constant ``−Tᵀ K p0`` of a model without rest
  shape).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

Array = NDArray[np.float64]
TERMS = ((0, 1, 0), (1, 0, 1), (2, 2, 0), (3, 1, 1), (4, 0, 2))
"""``(index into weights, a, b)`` of the stiffness terms ``w G^u_a ⊗ G^v_b``."""


@dataclass(frozen=True)
class KroneckerFactors:
    """Reduced 1-D Gram matrices of ``M_r`` and ``K_r`` (see the module docstring).

    Attributes
    ----------
    gram_u, gram_v : tuple of ndarray
        ``Ĝ_a = Tᵀ G_a T`` for ``a = 0, 1[, 2]`` (dense, ``(n', n')``).
    weights : tuple of float
        ``(w10, w01, w20, w11, w02)``.
    mass : float
        ``μ``.
    rigid_u, rigid_v : int
        ``dim null(Tᵀ (w10 G1 + w20 G2) T)`` in ``u`` (``w01``, ``w02`` in ``v``).
    """

    gram_u: tuple[Array, ...]
    gram_v: tuple[Array, ...]
    weights: tuple[float, float, float, float, float]
    mass: float
    rigid_u: int
    rigid_v: int

    def terms(self) -> list[tuple[float, int, int]]:
        """``(w, a, b)`` of the non-zero stiffness terms (``w = 2 w11`` for the twist)."""
        out = []
        for i, a, b in TERMS:
            w = self.weights[i] * (2 if i == 3 else 1)
            if w:
                out.append((w, a, b))
        return out

    @property
    def separable(self) -> bool:
        """Whether ``K_r = A_u ⊗ B_v + B_u ⊗ A_v`` (no twist term ``w11``)."""
        return self.weights[3] == 0


@dataclass(frozen=True)
class Reduction:
    """The constraint map of a net and the load offset of a model without rest shape.

    Attributes
    ----------
    T : sparse ``(n_points, n_free)``
        ``d = T d_free``.
    surface : Surface
        Where load fields are evaluated (``load.field_vector(surface, t)``).
    rest_force : ndarray ``(n_free, 3)`` or None
        Constant reduced force ``−Tᵀ K p0`` (``rest = "none"``), else ``None``.
    """

    T: sp.spmatrix
    surface: Any
    rest_force: Array | None = None
    columns = 3
    """Columns of a force: the 3 coordinates sharing ``T``, or 1 (interleaved rows)."""

    @property
    def n_free(self) -> int:
        """Number of free coordinates."""
        return int(self.T.shape[1])

    def field(self, term: Any, t: float = 0.0) -> Array:
        """Spatial vector ``F`` of one load term on the net, ``(n_points, 3)``."""
        return term.field_vector(self.surface, t)

    def reduce(self, F_full: Array) -> Array:
        """``Tᵀ F`` for a full force array ``(n_points, c)``."""
        return np.asarray(self.T.T @ F_full)
