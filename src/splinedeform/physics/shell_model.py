"""The Kirchhoff–Love shell as a model: :class:`splinedeform.Model` with the shell physics.

Boundary kinds per edge (``"u0"``, ``"u1"``, ``"v0"``, ``"v1"``): ``free``, ``pinned``,
``clamped``, ``diaphragm``, ``symmetry`` and ``pole``, imposed on the trace of the edge and
the derivative across it for any knot layout (:mod:`.shell_edges`). The matrices, the
constraint map, the free rigid motions and their handling, the static solve and the
read-out of stresses are the shell's formulation (:mod:`.shell_formulation`); static,
modes and dynamics are the model's, the same as the plate's.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from ..body.body import Body
from ..loads import Constant, Load, Profile, _profile, _vector3
from ..model import Model
from ..surface import Surface
from ..threads import owned
from . import metric
from .shell import ShellMaterial
from .shell_body import patch_index
from .shell_edges import EDGES, KINDS  # noqa: F401
from .shell_formulation import ShellFormulation
from .shell_stress import ShellStresses

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
        if surface.trim is not None:             # over the trimmed region, dA = √g du dv
            from ..loads import project

            return project(surface, lambda U, V: np.linalg.norm(np.cross(
                surface.derivative(U, V, 1, 0), surface.derivative(U, V, 0, 1)),
                axis=-1)[..., None] * np.asarray(self.force, dtype=float))
        G = metric.grid(surface, extra_points=1)
        N = metric.shape_derivatives(G)[0, 0]
        index = metric.global_index(G, surface.basis_v.size)
        weights = (G.weight * G.sqrt_g)[..., None] * N
        total = np.bincount(index.ravel(), weights.ravel(),
                            minlength=surface.shape[0] * surface.shape[1])
        return total[:, None] * np.asarray(self.force, dtype=float)[None, :]


class ShellModel(Model):
    """A linear Kirchhoff–Love shell on a B-spline surface (``physics = "shell"``).

    The one :class:`~splinedeform.Model` with the shell's formulation
    (:class:`.shell_formulation.ShellFormulation`): a state is the ``n_free`` reduced
    unknowns, x, y and z coupled; ``static``, ``eigen``, ``modes``, ``dynamic`` (method
    ``analytic``) are the model's.

    Parameters
    ----------
    surface : Surface, or Body (or list of Surface)
        One patch, or a body of patches deformed as one shell (:mod:`.shell_body`:
        conforming interfaces merged, their slopes tied where the rest shape is smooth
        across them, the others and every crease coupled by penalties); general NURBS
        weights (``net_weights``) included. Trimmed faces of a body are taken on their
        regions, coupled along the trim curves and trim edges they share
        (:mod:`.shell_body_trimmed`).
    material : ShellMaterial
    boundary : mapping edge -> kind, optional
        See the module docstring; missing edges are free. For a body one kind for every
        boundary edge, or ``{(patch, edge): kind}`` (a trimmed face's loops and trim edges
        keyed ``(face, "outer")``, ``(face, "hole1.0")`` …).
    fixed : bool array ``(n_u, n_v, 3)`` or ``(n_u, n_v)``, optional
        Individual displacement components (or whole control points) that do not move.
        For a body a sequence of one such mask (or None) per patch, as
        :class:`~splinedeform.body.BodyModel`'s ``fixed``: a control point that patches
        share (merged across a conforming interface) is held where any patch holds it.
        A trimmed surface or face (its map Höllig's extension, ``T = E ⊗ I₃``) takes a
        mask of whole points: ``(n_u, n_v)``, or per component with the three alike; a
        held inner or outer B-spline's coefficient stays at rest, a dead one (support
        outside the region) was at rest already
        (:mod:`splinedeform.trim.shell_trimmed`).
    """

    mass_matrix = "consistent"
    rest = "initial"
    gram_u = gram_v = None

    @owned
    def __init__(self, surface: Surface | Body | Sequence[Surface], material: ShellMaterial,
                 boundary: Mapping | str | None = None,
                 fixed: ArrayLike | Sequence[ArrayLike | None] | None = None):
        start = time.perf_counter()
        self.formulation = shell = ShellFormulation(surface, material, boundary, fixed)
        self.material, self.physics = material, "shell"
        self.surface, self.patches = shell.surface, shell.patches
        if shell.patches is not None:
            self.body, self.offsets = shell.body, shell.offsets
        self._full, self.edges = (shell.K_full, shell.M_full), shell.edges
        self._K = (shell.T.T @ shell.K_full @ shell.T).tocsc()
        self._M = (shell.T.T @ shell.M_full @ shell.T).tocsc()
        self._C = None
        self._finish(start)

    @property
    def T(self) -> sp.csr_matrix:
        """The constraint map ``d = T d_free`` over the interleaved unknowns."""
        return self.formulation.T

    @property
    def rigid(self) -> Array:
        """An orthonormal basis ``(n_free, k)`` of the free rigid motions (``null K_r``)."""
        return self.formulation.rigid_basis

    @property
    def rigid_motions(self) -> list[str]:
        """Words for a basis of the free rigid motions (rotation axes, translations)."""
        return self.formulation.rigid_motions

    def unknown_order(self) -> NDArray[np.int64]:
        """The reduced unknowns in nested dissection order of their control points."""
        return self.formulation.unknown_order(self._K)

    def spectrum_advice(self) -> str:
        """What to change when the shell's eigen-solution cannot be trusted."""
        return self.formulation.spectrum_advice()

    def nets(self, d_free: Array) -> Any:
        """Displacement nets ``T d_free`` of ``d_free (..., n_free)``: ``(..., n_u, n_v, 3)``,
        for a body a list of them, one per patch."""
        return self.readout.nets(np.asarray(d_free), rest=False)

    def stresses(self, displacement: ArrayLike, u: ArrayLike, v: ArrayLike,
                 at_poles: str = "raise", patch: int | None = None) -> ShellStresses:
        """Stresses of a displacement net ``(n_u, n_v, 3)`` (a solution's, a mode's) at ``u, v``.

        See :func:`.shell_stress.stresses`: ``N``, ``M`` in the local frame, ``σ`` at top,
        middle and bottom, principal and von Mises stresses, normal displacement;
        ``at_poles="nan"`` gives NaN at degenerate points instead of refusing them. On a
        body, ``displacement`` is the list of nets and ``patch`` says where ``u, v`` lie.
        """
        return self.readout.stresses(displacement, u, v, at_poles, patch)

    def patch_index(self, patch: int | None) -> int:
        """``patch`` checked as an index of a body's patches."""
        return patch_index(len(self.patches or ()), patch)
