"""A Kirchhoff–Love shell model: boundary conditions on ``3n`` coupled unknowns, solves.

Boundary kinds per edge (``"u0"``, ``"u1"``, ``"v0"``, ``"v1"``): ``free``, ``pinned``,
``clamped``, ``diaphragm``, ``symmetry`` and ``pole``, imposed on the trace of the edge and
the derivative across it for any knot layout (:mod:`.shell_edges`).

The rigid motions ``r = t + ω × p`` the boundary leaves free span ``null K_r`` (the shell's
energy vanishes on rigid motions only); every combination of translations and rotations
in ``range T`` is found (:func:`.shell_rigid.free_rigid_motions`). They are removed by
Lagrange multipliers ``∫ ρt d·r dA = 0`` (``M`` orthogonality to each), so a
self-equilibrated load on a free shell has its unique elastic answer; a static load that
does work on a free rigid motion has no equilibrium and is refused, naming the motion.
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
from ..loads import Constant, Harmonic, Load, Profile, _profile, _vector3, as_load, static_time
from ..solvers import modal_basis
from ..solvers.analytic import ModalResponse
from ..solvers.rigid import UnresolvedSpectrum
from ..surface import Surface
from ..threads import owned
from . import metric
from .coupling_model import c0_coupling
from .shell import ShellMaterial, matrices
from .shell_edges import EDGES, KINDS, check_edges, constraint_matrix  # noqa: F401
from .shell_rigid import describe, free_rigid_motions
from .shell_solve import dissection_ranks, static_displacement, unknown_order
from .shell_solution import ShellModalSolution, ShellStaticSolution
from .shell_stress import ShellStresses, stresses

Array = NDArray[np.float64]


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


class ShellModel:
    """A linear Kirchhoff–Love shell on a B-spline surface (``physics = "shell"``).

    Parameters
    ----------
    surface : Surface
    material : ShellMaterial
    boundary : mapping edge -> kind, optional
        See the module docstring; missing edges are free.
    fixed : bool array ``(n_u, n_v, 3)`` or ``(n_u, n_v)``, optional
        Individual displacement components (or whole control points) that do not move.
    """

    @owned
    def __init__(self, surface: Surface, material: ShellMaterial,
                 boundary: Mapping[str, str] | None = None, fixed: ArrayLike | None = None):
        start = time.perf_counter()
        if not isinstance(material, ShellMaterial):
            raise InputError("a shell needs a ShellMaterial(E, nu, thickness, density)")
        if getattr(surface, "trim", None) is not None:
            raise InputError("the shell is not trimmed yet: a trimmed surface takes the "
                             "parametric Model (docs/trim.md)")
        self.surface, self.material = surface, material
        self.physics = "shell"
        self.K_full, self.M_full = matrices(surface, material)
        self.edges = check_edges(surface, dict(boundary or {}))
        kinks = c0_coupling(surface, material, self.edges)
        if kinks is not None:                  # the crease kept across each C0 line
            self.K_full = (self.K_full + kinks).tocsr()
        self.T = constraint_matrix(surface, self.edges, fixed)
        self._K = (self.T.T @ self.K_full @ self.T).tocsc()
        self._M = (self.T.T @ self.M_full @ self.T).tocsc()
        self._C = (material.damping / (material.density * material.thickness) * self._M
                   + material.rayleigh * self._K).tocsc()
        motions = free_rigid_motions(self.T, surface.control_points)
        self.rigid = motions.reduced
        #: words for a basis of the free rigid motions (rotation axes, translations)
        self.rigid_motions = describe(motions.twists,
                                      float(np.ptp(surface.control_points.reshape(-1, 3),
                                                   axis=0).max()))
        self.timings = {"assembly": time.perf_counter() - start}

    @property
    def n_free(self) -> int:
        """Number of free displacement unknowns (x, y, z coupled)."""
        return self.T.shape[1]

    #: how summaries name :attr:`n_free` (a scalar model counts free control points)
    unknowns_label = "free unknowns (x, y, z coupled)"

    def matrices(self) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix]:
        """Reduced ``(M_r, C_r, K_r)``, each ``(n_free, n_free)``, ``C_r = (γ/(ρt)) M_r + β K_r``."""
        return self._M, self._C, self._K

    def load_vector(self, load: Load | None, t: float = 0.0) -> Array:
        """Reduced generalised force ``Tᵀ F(t)`` over the interleaved unknowns."""
        return np.asarray(self.T.T @ as_load(load).vector(self.surface, t).ravel())

    @owned
    def static(self, load: Load | None, t: float | None = None) -> ShellStaticSolution:
        """Equilibrium of the shell under ``load`` (at time ``t`` for a time-varying profile).

        ``K_r d = Tᵀ F``; free rigid motions ``r`` are removed by ``rᵀ M_r d = 0``.
        """
        start = time.perf_counter()
        F = self.load_vector(load, static_time(as_load(load), t))
        self._check_equilibrium(F)
        d = self._static_solve(F)
        return ShellStaticSolution(self, d, F, {"static": time.perf_counter() - start})

    def _check_equilibrium(self, F: Array) -> None:
        """Refuse a load doing work ``Fᵀ r`` on a free rigid motion ``r``: no equilibrium."""
        if self.rigid.shape[1] == 0:
            return
        work = np.abs(self.rigid.T @ F)
        if work.max() <= 1e-9 * max(np.linalg.norm(F), 1e-300):
            return
        held = {e: k for e, k in self.edges.items() if k != "free"} or "none"
        raise SingularSystemError(
            f"the shell's boundary (edges {held}) leaves {self.rigid.shape[1]} rigid "
            f"motion(s) free: {'; '.join(self.rigid_motions)}. The load does work on them, "
            "so no static equilibrium exists (the constrained stiffness is singular). Hold "
            "the shell against them (pin or clamp an edge, or fix components), or apply a "
            "self-equilibrated load")

    def unknown_order(self) -> NDArray[np.int64]:
        """The reduced unknowns in nested dissection order of their control points."""
        if getattr(self, "_order", None) is None:
            bu, bv = self.surface.basis_u, self.surface.basis_v
            rank = dissection_ranks(bu.size, bv.size, (bu.degree, bv.degree),
                                    bu.kind == "periodic", bv.kind == "periodic")
            self._order = unknown_order(self.T, rank, np.arange(self.n_free))
        return self._order

    def _static_solve(self, F: Array) -> Array:
        """Nested dissection and no pivoting (:mod:`.shell_solve`), else the bordered system."""
        d = static_displacement(self._K, self._M, self.rigid, F, self.unknown_order())
        if d is not None:
            return d
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
        return x[: self.n_free]

    def spectrum_advice(self) -> str:
        """What to change when the shell's eigen-solution cannot be trusted."""
        m = self.material
        return ("The shell's bending stiffness E t³/(12(1−ν²)) is t²/12 = "
                f"{m.thickness ** 2 / 12:.3g} (a length²) times its membrane stiffness E t/(1−ν²), so a thin shell on a "
                "fine net spreads its eigenvalues over many decades: raise the thickness "
                f"t = {m.thickness:g}, or use fewer cells or a lower degree. Young's modulus "
                f"E = {m.E:g} scales every eigenvalue alike and Poisson's ratio ν = {m.nu:g} "
                "hardly changes the spread, so neither helps. check_spectrum=False goes on "
                "with these modes at your own risk")

    def _guard(self, check_spectrum: bool) -> dict:
        return {"advice": self.spectrum_advice(),
                "guard": "residual" if check_spectrum else "off"}

    @owned
    def eigen(self, k: int, check_spectrum: bool = True) -> tuple[Array, Array]:
        """Lowest ``k`` eigenpairs of ``K_r φ = λ M_r φ`` (``Φᵀ M_r Φ = I``, rigid ``λ = 0``).

        Each computed pair is tested by its residual ``‖K_r φ − λ M_r φ‖`` (the error bounds
        of :mod:`splinedeform.solvers.eigen_trust`) and refused if its frequency or shape
        is not resolved; ``check_spectrum=False`` skips the test (at the caller's risk).
        """
        k = _count(k, self.n_free)
        if k > self.n_free // 2:
            basis = modal_basis.dense_basis(self._K, self._M, self.rigid.shape[1],
                                            **self._guard(check_spectrum))
            return basis.lam[:k], basis.phi[:, :k]
        basis = self._sparse_basis(k, check_spectrum)
        return basis.lam, basis.phi

    def _sparse_basis(self, k: int, check_spectrum: bool) -> modal_basis.DenseBasis:
        """The lowest ``k`` modes by shift-invert Lanczos, refusals in the shell's words."""
        try:
            return modal_basis.sparse_basis(self._K, self._M, k, None, self.rigid.shape[1],
                                            **self._guard(check_spectrum),
                                            order=self.unknown_order())
        except UnresolvedSpectrum:
            raise
        except SingularSystemError:
            raise SingularSystemError(
                "the shell's stiffness is singular for this boundary beyond its free rigid "
                f"motions ({'; '.join(self.rigid_motions) or 'none'}): some deformation "
                "costs no energy. Check the thickness, Young's modulus and the edges") from None

    def frequencies(self, k: int = 6, check_spectrum: bool = True) -> Array:
        """Lowest ``k`` angular frequencies ``ω = √λ`` (rigid ones 0); see :meth:`eigen`."""
        return np.sqrt(self.eigen(k, check_spectrum)[0])

    def modes(self, k: int = 6, check_spectrum: bool = True) -> tuple[Array, Array]:
        """Lowest ``k`` frequencies and mode shapes as control net displacements ``(k, n_u, n_v, 3)``."""
        lam, phi = self.eigen(k, check_spectrum)
        shapes = np.asarray(self.T @ phi).T.reshape((phi.shape[1],) + self.surface.shape + (3,))
        return np.sqrt(lam), shapes

    def stresses(self, displacement: ArrayLike, u: ArrayLike, v: ArrayLike,
                 at_poles: str = "raise") -> ShellStresses:
        """Stresses of a displacement net ``(n_u, n_v, 3)`` (a solution's, a mode's) at ``u, v``.

        See :func:`.shell_stress.stresses`: ``N``, ``M`` in the local frame, ``σ`` at top,
        middle and bottom, principal and von Mises stresses, normal displacement;
        ``at_poles="nan"`` gives NaN at degenerate points instead of refusing them.
        """
        return stresses(self.surface, self.material, displacement, u, v, at_poles)

    def _to_free(self, net: ArrayLike | None, what: str) -> Array:
        if net is None:
            return np.zeros(self.n_free)
        arr = np.asarray(net, dtype=float)
        if arr.shape != self.surface.shape + (3,):
            raise InputError(f"{what} must have shape (n_u, n_v, 3) = "
                             f"{self.surface.shape + (3,)}, got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise InputError(f"{what} must be finite")
        flat = arr.ravel()
        free = spla.spsolve((self.T.T @ self.T).tocsc(), self.T.T @ flat)
        if np.linalg.norm(self.T @ free - flat) > 1e-9 * max(np.linalg.norm(flat), 1e-300):
            raise InputError(f"{what} moves displacement components that the boundary "
                             "conditions fix or tie")
        return np.asarray(free)

    @owned
    def dynamic(self, load: Load | None, t_end: float, method: str = "analytic",
                modes: int | None = None, initial_displacement: ArrayLike | None = None,
                initial_velocity: ArrayLike | None = None,
                function_samples: int | None = None, check_spectrum: bool = True
                ) -> ShellModalSolution:
        """Motion on ``[0, t_end]`` in closed form, mode by mode.

        ``M_r d'' + C_r d' + K_r d = Tᵀ F(t)`` with ``C_r = (γ/(ρt)) M_r + β K_r``, so mode
        ``i`` has damping ``c_i = γ/(ρt) + β λ_i``; solved by
        :class:`~splinedeform.solvers.analytic.ModalResponse` for piecewise-constant and
        harmonic load profiles, from the initial displacement and velocity of the control
        net (default rest). All modes by dense ``eigh``, or with ``modes=k`` the lowest
        ``k`` by sparse Lanczos plus the exact static part of the omitted modes (mode
        acceleration) where the stiffness is not singular. ``function_samples`` is accepted
        for the scalar models' interface; shell loads have no time-dependent field.
        ``check_spectrum`` as for :meth:`eigen`.
        """
        start = time.perf_counter()
        if method != "analytic":
            raise InputError(f"the shell's dynamic solve is the closed-form modal one "
                             f"(method 'analytic'), got {method!r}")
        try:
            t_end = float(t_end)
        except (TypeError, ValueError):
            raise InputError(f"t_end must be a number, got {t_end!r}") from None
        if not np.isfinite(t_end) or t_end <= 0:
            raise InputError(f"t_end must be finite and > 0, got {t_end}")
        d0 = self._to_free(initial_displacement, "initial_displacement")
        v0 = self._to_free(initial_velocity, "initial_velocity")
        rigid = self.rigid.shape[1]
        if modes is None:
            if self.n_free > modal_basis.DENSE_MAX:
                raise InputError(f"all modes of {self.n_free} coupled unknowns need a dense "
                                 f"eigenproblem above the limit {modal_basis.DENSE_MAX}: give "
                                 "modes=k for the lowest modes plus the static correction")
            basis = modal_basis.dense_basis(self._K, self._M, rigid,
                                            **self._guard(check_spectrum))
        else:
            basis = self._sparse_basis(_count(modes, self.n_free), check_spectrum)
        load = as_load(load)
        jumps, harmonics = self._force_terms(load)
        project = lambda F: basis.project(F)[:, None]  # noqa: E731
        mat = self.material
        c = mat.damping / (mat.density * mat.thickness) + mat.rayleigh * basis.lam
        response = ModalResponse(basis.lam, c, project(self._M @ d0), project(self._M @ v0),
                                 [(t_j, project(F)) for t_j, F in jumps],
                                 [(w, phase, project(F)) for w, phase, F in harmonics])
        correction, truncation = None, {}
        if not basis.complete:
            truncation = {"modes": basis.size, "n_free": self.n_free,
                          "omega_max_kept": float(np.sqrt(basis.lam.max())),
                          "omega_first_omitted": float(np.sqrt(basis.first_omitted)),
                          "static_correction": basis.can_solve_static}
            if basis.can_solve_static:
                correction, indicators = modal_basis.mode_acceleration(
                    basis, self._K, self._M, [(t_j, F[:, None]) for t_j, F in jumps],
                    [(w, phase, F[:, None]) for w, phase, F in harmonics])
                truncation.update(indicators)
        timings = {**self.timings, "modal": time.perf_counter() - start}
        force = lambda t: self.load_vector(load, t)  # noqa: E731
        return ShellModalSolution(self, t_end, force, timings, basis, response, truncation,
                                  correction)

    def _force_terms(self, load: Load) -> tuple[list[tuple[float, Array]],
                                                list[tuple[float, float, Array]]]:
        """Reduced force as jumps ``(t_j, ΔF_j)`` and harmonics ``(Ω, φ, F)``."""
        jumps, harmonics = [], []
        for term in load.terms():
            if term.time_dependent_field:
                raise InputError("the shell's dynamic solve takes loads whose spatial field "
                                 "does not change with time")
            F = np.asarray(self.T.T @ term.field_vector(self.surface).ravel())
            if isinstance(term.profile, Harmonic):
                harmonics.append((term.profile.omega, term.profile.phase, F))
                continue
            steps = term.profile.jumps()
            if steps is None:
                raise InputError(f"load profile {type(term.profile).__name__} is neither "
                                 "piecewise constant nor harmonic")
            jumps += [(t_j, ds * F) for t_j, ds in steps]
        return jumps, harmonics


def _count(k: int, available: int) -> int:
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise InputError(f"number of modes must be an integer >= 1, got {k!r}")
    if k > available:
        raise InputError(f"asked for {k} modes but the shell has only {available} free "
                         "unknowns")
    return int(k)
