"""Read-out of a state in free coordinates: the rest surface (or a body's patches) and the
constraint map ``d = T d_free``, with the reduced ``M`` and ``K`` for the energies.

Control points are ``p = p_rest + T d_free``. With one unknown per control point
(``per_point = 1``, the plate) the three coordinates share ``T`` and a state is
``(..., n_free, 3)``; with three (``per_point = 3``, the shell) the rows of ``T`` are the
interleaved components (row ``3k + c``) and a state is ``(..., n_free)``. A body's rows of
``T`` are its patches' control points, patch after patch, each row-major.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray

from .errors import InputError
from .solvers.products import selected_rows
from .surface import Surface

Array = NDArray[np.float64]


class _Energies:
    """The reduced matrices of the energies, ``M`` and ``K``, and the layout of a state."""

    M: sp.spmatrix
    K: sp.spmatrix
    T: sp.spmatrix
    per_point: int

    def matrices(self) -> tuple[sp.spmatrix, sp.spmatrix]:
        """``(M, K)``."""
        return self.M, self.K

    @property
    def columns(self) -> int:
        """Columns of a state for the solvers: 3 coordinates sharing ``T``, or 1."""
        return 3 // self.per_point

    def from_columns(self, d: Array) -> Array:
        """A solver's state ``(..., n_free, columns)`` in this layout (see the module docstring)."""
        return d if self.per_point == 1 else d[..., 0]

    def _rows(self, arr: Array) -> Array:
        """A net ``(n_u, n_v, 3)`` as rows of ``T`` ``(N, 3)`` or interleaved ``(3N, 1)``."""
        return arr.reshape(-1, 3) if self.per_point == 1 else arr.reshape(-1, 1)

    def stresses(self, displacement: object, u: ArrayLike, v: ArrayLike,
                 at_poles: str = "raise", patch: int | None = None) -> object:
        """Stresses belong to the physics that has them (the shell)."""
        raise InputError("stresses are the Kirchhoff–Love shell's (physics 'shell'); the "
                         "plate under tension has none")


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
    per_point: int = 1

    def nets(self, d_free: Array, rest: bool = True) -> Array:
        """``[p_rest +] T d_free``: a state (module docstring) → ``(..., n_u, n_v, 3)``."""
        full = _expand(self.T, d_free, self.per_point)
        net = full.reshape(full.shape[:-2] + self.surface.shape + (3,))
        rest_points = self.surface.control_points
        if rest and net.dtype == np.result_type(net, rest_points):
            net += rest_points                          # a new array: added in place
        elif rest:
            net = rest_points + net
        return net

    def rows(self, net: ArrayLike, what: str) -> Array:
        """A displacement net ``(n_u, n_v, 3)`` as rows of ``T`` (:meth:`_rows`); the
        shape checked."""
        arr = np.asarray(net, dtype=float)
        if arr.shape != self.surface.shape + (3,):
            raise InputError(f"{what} must have shape (n_u, n_v, 3) = "
                             f"{self.surface.shape + (3,)}, got {arr.shape}")
        return self._rows(arr)

    def deformed(self, nets: Array, name: str) -> Surface:
        """The surface's bases with the control net ``nets``."""
        return self.surface.with_control_points(nets, name=name)

    def patch(self, nets: Array, patch: int | None) -> tuple[Surface, Array]:
        """The rest surface and ``nets`` (a single surface: ``patch`` None or 0)."""
        if patch not in (None, 0):
            raise InputError(f"a single surface has no patch {patch!r}")
        return self.surface, nets

    def mode_shapes(self, phi: Array) -> Array:
        """Mode shapes of ``phi (n_free, k)``: scalar fields ``(k, n_u, n_v)`` on the net
        (one unknown per point), control net displacements ``(k, n_u, n_v, 3)`` (three)."""
        if self.per_point == 3:
            return self.nets(np.asarray(phi).T, rest=False)
        return np.asarray(self.T @ phi).T.reshape((phi.shape[1],) + self.surface.shape)


@dataclass(frozen=True)
class BodyReadout(_Energies):
    """:class:`Readout` of a body: the patches' rest surfaces and one map ``d = T d_free``
    whose rows are the patches' control points, patch after patch (row-major in each)."""

    surfaces: tuple[Surface, ...]
    T: sp.spmatrix
    M: sp.spmatrix
    K: sp.spmatrix
    per_point: int = 1

    def nets(self, d_free: Array, rest: bool = True) -> list[Array]:
        """Per patch ``[p_rest +] T d_free``: a list of ``(..., n_u, n_v, 3)``."""
        full = _expand(self.T, d_free, self.per_point)
        sizes = [s.shape[0] * s.shape[1] for s in self.surfaces]
        parts = np.split(full, np.cumsum(sizes)[:-1], axis=-2)
        lead = full.shape[:-2]
        return [(s.control_points if rest else 0.0) + part.reshape(lead + s.shape + (3,))
                for s, part in zip(self.surfaces, parts)]

    def rows(self, net: ArrayLike, what: str) -> Array:
        """A list of per-patch displacement nets as rows of ``T``, patch after patch."""
        if not isinstance(net, (list, tuple)) or len(net) != len(self.surfaces):
            raise InputError(f"{what} of a body is a list of {len(self.surfaces)} nets, one "
                             "per patch")
        rows = []
        for p, (part, surface) in enumerate(zip(net, self.surfaces)):
            arr = np.asarray(part, dtype=float)
            if arr.shape != surface.shape + (3,):
                raise InputError(f"{what}[{p}] must have shape {surface.shape + (3,)}, got "
                                 f"{arr.shape}")
            rows.append(self._rows(arr))
        return np.concatenate(rows)

    def mode_shapes(self, phi: Array) -> list[Array]:
        """Mode shapes per patch: each ``(k, n_u, n_v)`` (one unknown per point) or
        ``(k, n_u, n_v, 3)`` (three)."""
        if self.per_point == 3:
            return self.nets(np.asarray(phi).T, rest=False)
        full = np.asarray(self.T @ phi).T
        sizes = [s.shape[0] * s.shape[1] for s in self.surfaces]
        parts = np.split(full, np.cumsum(sizes)[:-1], axis=1)
        return [part.reshape((phi.shape[1],) + s.shape) for part, s in zip(parts, self.surfaces)]

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


def _expand(T: sp.spmatrix, d_free: Array, per_point: int = 1) -> Array:
    """``T d_free`` → ``(..., n_points, 3)`` for ``d_free`` of shape ``(..., n_free, 3)``
    (``per_point = 1``) or ``(..., n_free)`` (``per_point = 3``, interleaved rows).

    Where ``T`` (one unknown per point) only selects points (one entry 1 per column, as for
    clamped or fixed control points) the product is a gather of rows of ``d_free``, with
    no transposed copies of it."""
    if per_point == 3:
        lead = d_free.shape[:-1]
        flat = np.moveaxis(d_free, -1, 0).reshape(T.shape[1], -1)
        full = np.asarray(T @ flat).reshape((T.shape[0],) + lead)
        return np.moveaxis(full, 0, -1).reshape(lead + (-1, 3))
    lead = d_free.shape[:-2]
    rows = selected_rows(T)
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


def free_coordinates(readout: Readout | BodyReadout, T: sp.spmatrix, net: ArrayLike | None,
                     what: str) -> Array:
    """Free coordinates ``(n_free, columns)`` of a displacement net (a body's: a list), by
    least squares ``Tᵀ T d_free = Tᵀ d``; refused where ``d`` is not in ``range T``."""
    if net is None:
        return np.zeros((T.shape[1], readout.columns))
    flat = readout.rows(net, what)
    if not np.all(np.isfinite(flat)):
        raise InputError(f"{what} must be finite")
    free = np.asarray(spla.spsolve((T.T @ T).tocsc(), T.T @ flat)).reshape(-1, flat.shape[1])
    if np.linalg.norm(T @ free - flat) > 1e-9 * max(np.linalg.norm(flat), 1e-300):
        raise InputError(f"{what} moves control points that the boundary conditions fix "
                         "or tie")
    return free
