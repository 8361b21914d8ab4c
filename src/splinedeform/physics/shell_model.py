"""A Kirchhoff–Love shell model: boundary conditions on ``3n`` coupled unknowns, solves.

Boundary kinds per edge (``"u0"``, ``"u1"``, ``"v0"``, ``"v1"``):

- ``free``; ``pinned``: the edge row of control points does not move; ``clamped``: the
  edge row and the next one do not move (no rotation);
- ``diaphragm``: rigid in its own plane, free out of it (Scordelis–Lo ends); the edge must
  lie in a coordinate plane ``x_c = const``; the two other components are fixed;
- ``symmetry``: the edge lies in a symmetry plane ``x_c = const``: component ``c`` of the
  edge row is fixed and the two others of the next row are tied to the edge row (zero slope
  across the plane).

Rigid motions left free by the boundary are removed by Lagrange multipliers
``∫ ρt d·r dA = 0`` (``M`` orthogonality to each free rigid motion ``r``), so a
self-equilibrated load on a free shell has its unique elastic answer.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, SingularSystemError
from ..loads import Constant, Harmonic, Load, Profile, _profile, _vector3, as_load
from ..solvers import modal_basis
from ..solvers.analytic import ModalResponse
from ..surface import Surface
from . import metric
from .shell import ShellMaterial, matrices

Array = NDArray[np.float64]
EDGES = ("u0", "u1", "v0", "v1")
KINDS = ("free", "pinned", "clamped", "diaphragm", "symmetry")


@dataclass(frozen=True)
class AreaForce(Load):
    """Force per unit *surface* area (e.g. self-weight ``ρ t g``): ``F_k = ∫ f N_k dA``."""

    force: ArrayLike = (0.0, 0.0, 0.0)
    profile: Profile = field(default_factory=Constant)

    def __post_init__(self) -> None:
        object.__setattr__(self, "force", _vector3(self.force, "AreaForce.force"))
        object.__setattr__(self, "profile", _profile(self.profile))

    def field_vector(self, surface: Surface, t: float = 0.0) -> Array:
        G = metric.grid(surface, extra_points=1)
        N = metric.shape_derivatives(G)[0, 0]
        index = metric.global_index(G, surface.basis_v.size)
        weights = (G.weight * G.sqrt_g)[..., None] * N
        total = np.bincount(index.ravel(), weights.ravel(),
                            minlength=surface.shape[0] * surface.shape[1])
        return total[:, None] * np.asarray(self.force, dtype=float)[None, :]


def _edge_rows(shape: tuple[int, int], edge: str, depth: int) -> NDArray[np.int64]:
    """Flat control point indices of row ``depth`` (0 = on the edge) of an edge, ``(len,)``."""
    grid = np.arange(shape[0] * shape[1]).reshape(shape)
    return {"u0": grid[depth], "u1": grid[-1 - depth], "v0": grid[:, depth],
            "v1": grid[:, -1 - depth]}[edge]


def _plane_axis(surface: Surface, edge: str, kind: str) -> int:
    P = surface.control_points.reshape(-1, 3)[_edge_rows(surface.shape, edge, 0)]
    spread = np.ptp(P, axis=0)
    axis = int(np.argmin(spread))
    if spread[axis] > 1e-9 * max(1.0, float(np.abs(P).max())):
        raise InputError(f"a {kind} edge must lie in a coordinate plane (x, y or z constant); "
                         f"edge {edge} of {surface.name!r} spreads {spread} in x, y, z")
    return axis


def constraint_matrix(surface: Surface, boundary: Mapping[str, str], fixed: Array | None
                      ) -> sp.csr_matrix:
    """``T`` with ``d = T d_free`` over the interleaved ``3n`` displacements."""
    n = surface.shape[0] * surface.shape[1]
    parent = np.arange(3 * n)
    is_fixed = np.zeros(3 * n, bool) if fixed is None else np.asarray(fixed, bool).ravel().copy()
    if is_fixed.size != 3 * n:
        raise InputError(f"fixed must be a boolean mask of shape {surface.shape + (3,)}")
    for edge, kind in boundary.items():
        if edge not in EDGES or kind not in KINDS:
            raise InputError(f"shell boundary: edge must be one of {EDGES} and kind one of "
                             f"{KINDS}, got {edge!r}: {kind!r}")
        row0, row1 = _edge_rows(surface.shape, edge, 0), _edge_rows(surface.shape, edge, 1)
        if kind in ("pinned", "clamped"):
            for row in (row0, row1)[: 1 + (kind == "clamped")]:
                is_fixed[(3 * row[:, None] + np.arange(3)).ravel()] = True
        elif kind == "diaphragm":
            axis = _plane_axis(surface, edge, kind)
            is_fixed[(3 * row0[:, None] + np.delete(np.arange(3), axis)).ravel()] = True
        elif kind == "symmetry":
            axis = _plane_axis(surface, edge, kind)
            is_fixed[3 * row0 + axis] = True
            for c in np.delete(np.arange(3), axis):
                parent[3 * row1 + c] = parent[3 * row0 + c]
    parent = parent[parent]                     # ties are one level deep (row1 → row0)
    keep = ~is_fixed[parent]
    columns = np.unique(parent[keep])
    col_of = np.full(3 * n, -1)
    col_of[columns] = np.arange(columns.size)
    rows = np.nonzero(keep)[0]
    return sp.csr_matrix((np.ones(rows.size), (rows, col_of[parent[rows]])),
                         shape=(3 * n, columns.size))


class ShellModel:
    """A linear Kirchhoff–Love shell on a B-spline surface (``physics = "shell"``).

    Parameters
    ----------
    surface : Surface
    material : ShellMaterial
    boundary : mapping edge -> kind, optional
        See the module docstring; missing edges are free.
    fixed : bool array ``(n_u, n_v, 3)``, optional
        Individual displacement components that do not move.
    """

    def __init__(self, surface: Surface, material: ShellMaterial,
                 boundary: Mapping[str, str] | None = None, fixed: ArrayLike | None = None):
        start = time.perf_counter()
        if not isinstance(material, ShellMaterial):
            raise InputError("a shell needs a ShellMaterial(E, nu, thickness, density)")
        self.surface, self.material = surface, material
        self.K_full, self.M_full = matrices(surface, material)
        self.T = constraint_matrix(surface, dict(boundary or {}), fixed)
        self._K = (self.T.T @ self.K_full @ self.T).tocsc()
        self._M = (self.T.T @ self.M_full @ self.T).tocsc()
        self.rigid = self._free_rigid_motions()
        self.timings = {"assembly": time.perf_counter() - start}

    @property
    def n_free(self) -> int:
        """Number of free displacement unknowns (x, y, z coupled)."""
        return self.T.shape[1]

    def matrices(self) -> tuple[sp.csc_matrix, sp.csc_matrix]:
        """Reduced ``(M_r, K_r)``, each ``(n_free, n_free)``."""
        return self._M, self._K

    def _free_rigid_motions(self) -> Array:
        """Reduced rigid motions (translations, rotations ``ω × p``) the boundary leaves free."""
        P = self.surface.control_points.reshape(-1, 3)
        motions = [np.tile(np.eye(3)[c], (P.shape[0], 1)) for c in range(3)]
        motions += [np.cross(np.eye(3)[c], P) for c in range(3)]
        R = np.stack([m.ravel() for m in motions], axis=1)
        reduced = np.column_stack([spla.lsqr(self.T, R[:, i], atol=1e-14, btol=1e-14)[0]
                                   for i in range(6)])
        residual = np.linalg.norm(self.T @ reduced - R, axis=0) / np.linalg.norm(R, axis=0)
        # combinations of the rigid motions that the constraints allow exactly
        candidates = reduced[:, residual < 1e-8]
        if candidates.shape[1] == 0:
            return np.zeros((self.n_free, 0))
        u, s, _ = np.linalg.svd(candidates, full_matrices=False)
        return u[:, s > 1e-10 * s.max()]

    def load_vector(self, load: Load | None) -> Array:
        """Reduced generalised force ``Tᵀ F`` over the interleaved unknowns."""
        return np.asarray(self.T.T @ as_load(load).vector(self.surface, 0.0).ravel())

    def static(self, load: Load | None) -> Array:
        """Equilibrium displacement of the control net, ``(n_u, n_v, 3)``.

        ``K_r d = Tᵀ F``; free rigid motions ``r`` are removed by ``rᵀ M_r d = 0``.
        """
        F = self.load_vector(load)
        C = self._M @ self.rigid
        k = C.shape[1]
        A = sp.bmat([[self._K, sp.csr_matrix(C)], [sp.csr_matrix(C.T), None]], format="csc")
        rhs = np.concatenate([F, np.zeros(k)])
        try:
            x = spla.splu(A).solve(rhs)
        except RuntimeError:
            raise SingularSystemError("the shell's stiffness is singular for this boundary: "
                                      "some deformation other than a rigid motion costs no "
                                      "energy") from None
        d = x[: self.n_free]
        return np.asarray(self.T @ d).reshape(self.surface.shape + (3,))

    def frequencies(self, k: int = 6) -> Array:
        """Lowest ``k`` angular frequencies ``ω = √λ`` of ``K_r φ = λ M_r φ`` (rigid ones 0)."""
        basis = modal_basis.sparse_basis(self._K, self._M, k, None, self.rigid.shape[1])
        return np.sqrt(basis.lam[:k])

    def dynamic(self, load: Load | None, times: ArrayLike, damping: float = 0.0,
                modes: int | None = None) -> Array:
        """Control net displacements ``(F, n_u, n_v, 3)`` at ``times``, from rest, in closed form.

        ``M_r d'' + C_r d' + K_r d = Tᵀ F(t)`` with ``C_r = damping · M_r`` (modal damping
        ``c_i = damping``), solved mode by mode (:class:`~splinedeform.solvers.analytic.ModalResponse`)
        for piecewise-constant and harmonic load profiles. All modes by dense ``eigh`` or,
        with ``modes=k``, the lowest ``k`` by sparse Lanczos (no static correction).
        """
        damping = float(damping)
        if not np.isfinite(damping) or damping < 0:
            raise InputError(f"shell damping must be finite and >= 0, got {damping!r}")
        if modes is None:
            basis = modal_basis.dense_basis(self._K, self._M, self.rigid.shape[1])
        else:
            basis = modal_basis.sparse_basis(self._K, self._M, int(modes), None,
                                             self.rigid.shape[1])
        jumps, harmonics = [], []
        for term in as_load(load).terms():
            if term.time_dependent_field:
                raise InputError("the shell's dynamic solve takes loads whose spatial field "
                                 "does not change with time")
            g = basis.project(np.asarray(self.T.T @ term.field_vector(self.surface).ravel()))
            if isinstance(term.profile, Harmonic):
                harmonics.append((term.profile.omega, term.profile.phase, g[:, None]))
                continue
            steps = term.profile.jumps()
            if steps is None:
                raise InputError(f"load profile {type(term.profile).__name__} is neither "
                                 "piecewise constant nor harmonic")
            jumps += [(t_j, ds * g[:, None]) for t_j, ds in steps]
        n = basis.lam.size
        response = ModalResponse(basis.lam, np.full(n, damping), np.zeros((n, 1)),
                                 np.zeros((n, 1)), jumps, harmonics)
        Q, _ = response(np.asarray(times, dtype=float).ravel())
        d = np.einsum("ij,fj->fi", basis.phi, Q[..., 0])
        full = np.asarray(self.T @ d.T).T
        return full.reshape((-1,) + self.surface.shape + (3,))
