"""Read-out of a state in free coordinates: the rest surface (or a body's patches) and the
constraint map ``d = T d_free``, with the reduced ``M`` and ``K`` for the energies.

Control points are ``p = p_rest + T d_free`` (three coordinates share ``T``); a body's rows of
``T`` are its patches' control points, patch after patch, each row-major.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .errors import InputError
from .surface import Surface

Array = NDArray[np.float64]


class _Energies:
    """The reduced matrices of the energies, ``M`` and ``K``."""

    M: sp.spmatrix
    K: sp.spmatrix

    def matrices(self) -> tuple[sp.spmatrix, sp.spmatrix]:
        """``(M, K)``."""
        return self.M, self.K


@dataclass(frozen=True)
class Readout(_Energies):
    """What a solution needs to read its free coordinates out as a surface.

    Attributes
    ----------
    surface : Surface
        The rest surface (control points ``p_rest``, bases for evaluation).
    T : sparse ``(n_u n_v, n_free)``
        The constraint map ``d = T d_free``.
    M, K : sparse ``(n_free, n_free)``
        Reduced mass and stiffness, for the energies.
    """

    surface: Surface
    T: sp.spmatrix
    M: sp.spmatrix
    K: sp.spmatrix

    def nets(self, d_free: Array, rest: bool = True) -> Array:
        """``[p_rest +] T d_free``: ``(..., n_free, 3)`` → ``(..., n_u, n_v, 3)``."""
        net = _expand(self.T, d_free).reshape(d_free.shape[:-2] + self.surface.shape + (3,))
        rest_points = self.surface.control_points
        if rest and net.dtype == np.result_type(net, rest_points):
            net += rest_points                          # a new array: added in place
        elif rest:
            net = rest_points + net
        return net


@dataclass(frozen=True)
class BodyReadout(_Energies):
    """:class:`Readout` of a body: the patches' rest surfaces and one map ``d = T d_free``
    whose rows are the patches' control points, patch after patch (row-major in each)."""

    surfaces: tuple[Surface, ...]
    T: sp.spmatrix
    M: sp.spmatrix
    K: sp.spmatrix

    def nets(self, d_free: Array, rest: bool = True) -> list[Array]:
        """Per patch ``[p_rest +] T d_free``: a list of ``(..., n_u, n_v, 3)``."""
        full = _expand(self.T, d_free)
        sizes = [s.shape[0] * s.shape[1] for s in self.surfaces]
        parts = np.split(full, np.cumsum(sizes)[:-1], axis=-2)
        lead = d_free.shape[:-2]
        return [(s.control_points if rest else 0.0) + part.reshape(lead + s.shape + (3,))
                for s, part in zip(self.surfaces, parts)]

    def deformed(self, nets: list[Array], name: str) -> list[Surface]:
        """Each patch's bases with its control net."""
        return [s.with_control_points(n, name=name) for s, n in zip(self.surfaces, nets)]

    def patch(self, nets: list[Array], patch: int | None) -> tuple[Surface, Array]:
        """The rest surface and the nets of patch ``patch``."""
        if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) \
                or not 0 <= patch < len(self.surfaces):
            raise InputError(f"a body's displacement needs its patch: an index in "
                             f"[0, {len(self.surfaces) - 1}], got {patch!r}")
        return self.surfaces[patch], nets[patch]

    def probe(self, nets: list[Array], patch: int, u: float, v: float) -> Array:
        """Displacement ``d_f(u, v) = Σ_kl N_kl(u, v) (P_f − P_rest)_kl`` of the point
        ``(u, v)`` of patch ``patch`` in every frame, for per-patch nets ``(F, n_u, n_v, 3)``
        (rest included): ``(F, 3)``."""
        surface, P = self.patch(nets, patch)
        D = np.asarray(P, dtype=float) - surface.control_points
        E = surface.evaluation_matrix(np.array([u], dtype=float), np.array([v], dtype=float))
        F = D.shape[0]
        flat = np.moveaxis(D.reshape(F, -1, 3), 0, 1).reshape(E.shape[1], F * 3)
        return np.asarray(E @ flat).reshape(F, 3)


def _expand(T: sp.spmatrix, d_free: Array) -> Array:
    """``T d_free`` for ``d_free`` of shape ``(..., n_free, 3)`` → ``(..., n_points, 3)``.

    Where ``T`` only selects points (one entry 1 per column, as for clamped or fixed
    control points) the product is a gather of rows of ``d_free``, with no transposed
    copies of it."""
    lead = d_free.shape[:-2]
    rows = _selected_rows(T)
    if rows is not None:                # gather each point's free row, zero the others
        source = np.zeros(T.shape[0], dtype=np.intp)
        source[rows] = np.arange(rows.size)
        fixed = np.ones(T.shape[0], dtype=bool)
        fixed[rows] = False
        full = np.take(d_free, source, axis=-2)
        full[..., fixed, :] = 0.0
        return full
    flat = np.moveaxis(d_free, -2, 0).reshape(T.shape[1], -1)
    return np.moveaxis((T @ flat).reshape((T.shape[0],) + lead + (3,)), 0, -2)


def _selected_rows(T: sp.spmatrix) -> NDArray[np.int64] | None:
    """The row of each column of ``T`` when ``T`` is a selection (one entry 1 per column,
    distinct rows), else ``None``."""
    if not sp.issparse(T) or T.nnz != T.shape[1]:
        return None
    C = T.tocsc()
    if not (np.all(np.diff(C.indptr) == 1) and np.all(C.data == 1.0)):
        return None
    rows = np.asarray(C.indices)
    return rows if np.unique(rows).size == rows.size else None
