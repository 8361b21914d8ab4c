"""The Kirchhoff–Love shell as a :class:`~.formulation.Formulation`.

Three unknowns per control point, interleaved (row ``3k + c`` of ``T`` is component ``c``
of control point ``k``), coupled by the shell's energy (:mod:`.shell`); a free state is
``(n_free,)``. On one surface ``T`` imposes the edge kinds (:mod:`.shell_edges`); on a body
of patches :mod:`.shell_body` merges conforming interfaces and couples the others by
penalties. Across every conforming line where the rest shape is smooth (a ``C^0`` knot line
inside a patch, a conforming interface or seam of a body) ``T`` also ties the slopes
exactly (:mod:`.coupling_ties`), so the rotation is continuous there; creases and
non-conforming interfaces keep the rotation penalty (:mod:`.coupling_model`). Damping ``C_r = (γ/(ρt)) M_r + β K_r``.

The rigid motions ``r = t + ω × p`` the boundary leaves free span ``null K_r`` (the shell's
energy vanishes on rigid motions only); every combination of translations and rotations
in ``range T`` is found (:func:`.shell_rigid.free_rigid_motions`) and is
:attr:`ShellFormulation.rigid_basis`. They are removed by ``Rᵀ M_r d = 0``, so a
self-equilibrated load on a free shell has its unique elastic answer; a static load that
does work on a free rigid motion has no equilibrium and is refused, naming the motion
(:meth:`ShellFormulation.static_displacement`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..body.body import Body
from ..body.constraints import body_fixed_mask, trimmed_face_masks
from ..body.loads import surface_field
from ..errors import InputError, SingularSystemError
from ..solvers.system import Reduction
from ..surface import Surface
from .coupling_model import c0_coupling
from .coupling_ties import smooth_ties, tie_components
from .shell import ShellMaterial, matrices
from .shell_body import body_field, body_system
from .shell_clamp import clamp_rotation, held
from .shell_edges import check_edges, constraint_matrix
from .shell_rigid import describe, free_rigid_motions
from .shell_solution import ShellBodyReadout, ShellReadout
from .shell_solve import dissection_ranks, static_displacement, unknown_order

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShellReduction(Reduction):
    """Load fields of the shell on the interleaved rows of ``T``, one column ``(3N, 1)``;
    on a body, ``signs`` is its :attr:`~splinedeform.body.Body.orientation`
    (:func:`.shell_body.body_field`)."""

    signs: tuple[int, ...] = ()
    columns = 1

    def field(self, term: Any, t: float = 0.0) -> Array:
        if isinstance(self.surface, Surface):
            return np.asarray(surface_field(term, self.surface, t)).reshape(-1, 1)
        return body_field(self.surface, term, t, self.signs)[:, None]


class ShellFormulation:
    """The shell on one surface or a body of patches (see the module docstring).

    Parameters
    ----------
    surface : Surface, or Body (or list of Surface)
    material : ShellMaterial
    boundary : mapping edge -> kind, optional
        For a body one kind for every boundary edge, or ``{(patch, edge): kind}``.
    fixed : bool array ``(n_u, n_v, 3)`` or ``(n_u, n_v)``, optional
        Displacement components (or whole control points) that do not move; for a body
        one such mask (or None) per patch
        (:func:`~splinedeform.body.constraints.body_fixed_mask`).

    Attributes
    ----------
    K_full, M_full : sparse ``(3N, 3N)``
    T : sparse ``(3N, n_free)``
    edges : dict
        The kind of each edge (a body's keyed ``(patch, edge)``).
    ties : :class:`~.coupling_ties.Ties`
        The smooth lines whose slopes ``T`` ties exactly (the others keep the penalty).
    """

    physics = "shell"
    per_point = 3
    unknowns_label = "free unknowns (x, y, z coupled)"
    methods = ("analytic",)

    def __init__(self, surface: Surface | Body | Sequence[Surface], material: ShellMaterial,
                 boundary: Mapping | str | None = None,
                 fixed: ArrayLike | Sequence[ArrayLike | None] | None = None):
        if not isinstance(material, ShellMaterial):
            raise InputError("a shell needs a ShellMaterial(E, nu, thickness, density)")
        self.material = material
        motions = None
        if isinstance(surface, (Body, list, tuple)):
            self.body = surface if isinstance(surface, Body) else Body(surface)
            mask = body_fixed_mask(self.body.patches, fixed, components=True)
            kind = "free" if boundary is None else boundary
            if any(s.trim is not None for s in self.body.patches):   # :mod:`.shell_body_trimmed`
                from .shell_body_trimmed import trimmed_body_system

                system = trimmed_body_system(
                    self.body, material, kind, fixed=mask,
                    face_fixed=trimmed_face_masks(self.body.patches, fixed, components=True))
            else:
                system = body_system(self.body, material, kind, fixed=mask)
            motions = system.motions
            self.patches: tuple[Surface, ...] | None = self.body.patches
            self.surface, self.offsets = None, system.offsets
            self.K_full, self.M_full, self.T, self.edges = (system.K, system.M, system.T,
                                                            system.edges)
            self.ties = system.ties
            points = np.concatenate([s.control_points.reshape(-1, 3) for s in self.patches])
            if system.clamps:                      # a curved patch's clamped edges
                motions = held(self.T)
        elif getattr(surface, "trim", None) is not None:     # loops held by Nitsche
            from ..trim.shell_trimmed import trimmed_shell

            trim = trimmed_shell(surface, material, boundary, fixed)
            self.surface, self.patches, points = surface, None, surface.control_points
            self.K_full, self.M_full, self.T, self.edges = (trim.stiffness, trim.mass, trim.T,
                                                            trim.edges)
            motions = trim.motions
            self.ties = smooth_ties([surface], (), np.array([0, surface.shape[0]
                                                             * surface.shape[1]]))
        else:
            if isinstance(boundary, str):
                raise InputError("a single surface's shell boundary is a mapping edge -> "
                                 f"kind, got {boundary!r}")
            self.surface, self.patches = surface, None
            self.K_full, self.M_full = matrices(surface, material)
            self.edges = check_edges(surface, dict(boundary or {}))
            self.ties = smooth_ties([surface], (), np.array([0, surface.shape[0]
                                                             * surface.shape[1]]))
            kinks = c0_coupling(surface, material, self.edges,
                                exact={(d, k) for _, d, k in self.ties.lines})
            if kinks is not None:                  # the crease kept across each C0 line
                self.K_full = (self.K_full + kinks).tocsr()
            rotation = clamp_rotation(surface, material, self.edges)
            if rotation is not None:               # a curved shell's clamped edges
                self.K_full = (self.K_full + rotation).tocsr()
            # the slopes tied exactly across each smooth C0 line
            self.T = tie_components(constraint_matrix(surface, self.edges, fixed, True),
                                    self.ties.C)
            points = surface.control_points
            if rotation is not None:               # a rigid motion at rest on a clamped
                motions = held(self.T)             # edge turns about it: Nitsche holds it
        if motions is None:
            motions = free_rigid_motions(self.T, points)
        self.rigid_basis: Array = motions.reduced
        #: words for a basis of the free rigid motions (rotation axes, translations)
        self.rigid_motions = describe(motions.twists,
                                      float(np.ptp(points.reshape(-1, 3), axis=0).max()))
        self._order: NDArray[np.int64] | None = None

    @property
    def damping_rate(self) -> float:
        """``γ/(ρt)``."""
        m = self.material
        return m.damping / (m.density * m.thickness)

    @property
    def rayleigh(self) -> float:
        """``β``."""
        return self.material.rayleigh

    def reduction(self, T: sp.spmatrix, rest: Array | None) -> ShellReduction:
        if self.patches is None:
            return ShellReduction(T, self.surface, rest)
        return ShellReduction(T, self.patches, rest, self.body.orientation)

    def readout(self, T: sp.spmatrix, M_r: sp.spmatrix, K_r: sp.spmatrix) -> Any:
        if self.patches is None:
            return ShellReadout(self.surface, T, M_r, K_r, 3, self.material)
        return ShellBodyReadout(self.patches, T, M_r, K_r, 3, self.material)

    # -- static ------------------------------------------------------------------------
    def check_equilibrium(self, F: Array) -> None:
        """Refuse a load doing work ``Fᵀ r`` on a free rigid motion ``r``: no equilibrium."""
        R = self.rigid_basis
        if R.shape[1] == 0:
            return
        work = np.abs(R.T @ F)
        if work.max() <= 1e-9 * max(np.linalg.norm(F), 1e-300):
            return
        held = {e: k for e, k in self.edges.items() if k != "free"} or "none"
        raise SingularSystemError(
            f"the shell's boundary (edges {held}) leaves {R.shape[1]} rigid "
            f"motion(s) free: {'; '.join(self.rigid_motions)}. The load does work on them, "
            "so no static equilibrium exists (the constrained stiffness is singular). Hold "
            "the shell against them (pin or clamp an edge, or fix components), or apply a "
            "self-equilibrated load")

    def static_displacement(self, model: Any, F: Array) -> Array:
        """``K_r d = F`` with ``Rᵀ M_r d = 0``: nested dissection and no pivoting
        (:mod:`.shell_solve`), else the bordered system ``[[K_r, M_r R], [Rᵀ M_r, 0]]``."""
        self.check_equilibrium(F)
        M, _, K = model.matrices()
        R = self.rigid_basis
        d = static_displacement(K, M, R, F, self.unknown_order(K))
        if d is not None:
            return d
        C = M @ R
        A = sp.bmat([[K, sp.csr_matrix(C)], [sp.csr_matrix(C.T), None]], format="csc")
        try:
            x = spla.splu(A).solve(np.concatenate([F, np.zeros(C.shape[1])]))
        except RuntimeError:
            raise SingularSystemError("the shell's stiffness is singular for this boundary: "
                                      "some deformation other than a rigid motion costs no "
                                      "energy") from None
        return x[: K.shape[0]]

    def unknown_order(self, K_r: sp.spmatrix) -> NDArray[np.int64]:
        """The reduced unknowns in nested dissection order of their control points (a
        body's: reverse Cuthill–McKee of ``K_r``)."""
        if self._order is None and self.patches is not None:
            self._order = np.asarray(reverse_cuthill_mckee(sp.csr_matrix(K_r),
                                                           symmetric_mode=True),
                                     dtype=np.int64)
        if self._order is None:
            bu, bv = self.surface.basis_u, self.surface.basis_v
            rank = dissection_ranks(bu.size, bv.size, (bu.degree, bv.degree),
                                    bu.kind == "periodic", bv.kind == "periodic")
            self._order = unknown_order(self.T, rank, np.arange(self.T.shape[1]))
        return self._order

    # -- modes -------------------------------------------------------------------------
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

    def eigen_options(self, K_r: sp.spmatrix, check_spectrum: bool) -> dict[str, Any]:
        """Every pair tested by its residual (:mod:`splinedeform.solvers.eigen_trust`),
        the advice in the shell's words, the nested dissection order for the factor."""
        return {"advice": self.spectrum_advice(),
                "guard": "residual" if check_spectrum else "off",
                "order": self.unknown_order(K_r)}
