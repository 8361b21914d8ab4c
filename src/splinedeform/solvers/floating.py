"""Equilibrium of a free-floating structure under a self-equilibrated load.

Where nothing holds a structure, ``K`` vanishes on its rigid motions ``Z`` (``K Z = 0``)
and ``K d = F`` has a solution only when the load does no work on them, ``Zᵀ F = 0`` (a
closed body under internal pressure: ``∮ n dA = 0``). The solution is then unique up to
a rigid motion, which is fixed by asking the mass-weighted mean motion to vanish:

.. math::

    \\begin{pmatrix} K & M Z \\\\ Z^T M & 0 \\end{pmatrix}
    \\begin{pmatrix} d \\\\ \\lambda \\end{pmatrix} =
    \\begin{pmatrix} F \\\\ 0 \\end{pmatrix},

whose multiplier is ``λ = 0`` when ``Zᵀ F = 0`` (multiply the first row by ``Zᵀ``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import SingularSystemError

Array = NDArray[np.float64]

#: largest resultant ``|Zᵀ F|`` of a self-equilibrated load, relative to ``Σ |F|`` times
#: ``|Z|``: a closed surface's load sums to zero up to round-off of its quadrature
RESULTANT_TOLERANCE = 1e-9


def floating_static(K: sp.spmatrix, M: sp.spmatrix, F: Array, Z: Array) -> Array:
    """``d`` with ``K d = F`` and ``Zᵀ M d = 0`` (module docstring).

    Parameters
    ----------
    K, M : sparse ``(n, n)``
        Stiffness (singular on ``Z``) and mass.
    F : ndarray ``(n, c)``
        Load, one column per coordinate.
    Z : ndarray ``(n, r)``
        The rigid motions, ``K Z = 0``.

    Raises
    ------
    SingularSystemError
        When the load has a resultant on the rigid motions (the structure would accelerate).
    """
    F = np.asarray(F, dtype=float)
    columns = F.reshape(F.shape[0], -1)
    resultant = np.abs(Z.T @ columns)
    scale = np.abs(columns).sum(axis=0) * np.linalg.norm(Z, axis=0).max()
    if np.any(resultant > RESULTANT_TOLERANCE * np.maximum(scale, 1e-300)):
        raise SingularSystemError(
            "static solve of a free body: nothing holds it and the load has a resultant "
            f"(largest {resultant.max():.3g} against a total load of {scale.max():.3g}), so it "
            "would accelerate without end; hold a boundary edge (pinned or clamped) or give "
            "a self-equilibrated load (a pressure on a closed body)")
    MZ = sp.csr_matrix(M @ Z)
    r = Z.shape[1]
    system = sp.bmat([[K, MZ], [MZ.T, sp.csr_matrix((r, r))]], format="csc")
    rhs = np.vstack([columns, np.zeros((r, columns.shape[1]))])
    solution = spla.splu(system).solve(rhs)
    return solution[:F.shape[0]].reshape(F.shape)
