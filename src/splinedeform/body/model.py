"""A body of patches deformed as one model: one energy, one constraint map, one solve.

:class:`BodyModel` is the single-surface model (:class:`splinedeform.Model`: static, modes,
the closed-form and numerical dynamics) on the system of the plate of a body, assembled
by :func:`splinedeform.physics.plate_body.body_system`: the patches' own matrices on the
diagonal, the couplings across interfaces, C0 lines and shared trim curves, and the
constraint map ``d = T d_free`` that merges conforming interfaces and poles,
``K_r = Tᵀ K T``, ``M_r = Tᵀ M T``, ``F_r = Tᵀ F``.
"""

from __future__ import annotations

import time
from typing import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ..model import Model, check_options
from ..material import Material
from ..physics.plate_body import body_system, known_fields, rigid_count
from ..solvers.rigid import UnresolvedSpectrum, null_space
from ..surface import Surface
from .body import Body

__all__ = ["BodyModel"]

Array = NDArray[np.float64]


class BodyModel(Model):
    """Patches of a :class:`.Body` with one material, deformed as one connected surface.

    Parameters
    ----------
    body : Body or list of Surface
        A list is made a body with its interfaces found geometrically.
    material : Material
    boundary : str or mapping, default "free"
        ``"free" | "pinned" | "clamped"`` for every boundary edge (an edge no other edge
        meets), or ``{(patch, edge): preset}`` (missing boundary edges are free). Interface
        and pole edges have no preset: they are merged or coupled (Notes). A trimmed face's
        loops are keyed ``(patch, "outer")``, ``(patch, "hole1")`` …; a loop it shares with
        another face (:attr:`.Body.trim_interfaces`) has no preset either.
    fixed : sequence of bool arrays or None, optional
        One mask per patch, of the shape ``(n_u, n_v)`` of its control net, ``True`` =
        the control point is held at rest (the paper's reduced set of moving control
        points, as :class:`splinedeform.Model`'s ``fixed``); ``None`` for a patch with
        nothing fixed beyond its edges. A control point that several patches share (merged
        across a conforming interface, or on a pole) is fixed when any one of them fixes
        it. A point that its edge condition determines from others follows that condition.
        On a trimmed face the mask is taken by the face's own map, as a single trimmed
        surface's (:func:`~splinedeform.trim.holed.with_edges`): a held inner B-spline
        (an unknown of Höllig's extension) stays at rest, and so does a held outer one
        (its coefficient no longer follows the inner ones; the other outer ones are tied
        to free inner ones only), while a dead one (support outside the region) was at
        rest already and holds nothing. No point of a trimmed face is merged with another
        face's (trim curves are coupled by penalties), so it is held in its face alone.
    mass_matrix : {"consistent", "lumped"}
    rest : {"initial", "none"}
    physics : {"intrinsic", "parametric"}, default "intrinsic"
        ``intrinsic`` measures the energy on the initial surface, the same on every patch
        whatever its parametrisation. ``parametric`` (the paper's energy per unit parameter
        area) depends on each patch's parametrisation: two patches of one surface
        parametrised differently (a reversed or rescaled direction of a curved patch, a
        different parameter length) get different energies, so the body is a different
        material patch by patch; use it only where the patches are parametrised alike.

    Raises
    ------
    InputError
        For a non-manifold edge (three or more patches on one edge), or an interface whose
        two edges are parametrised differently along the curve (not an affine map); for
        ``fixed`` of another count than one per patch, or a mask of another shape than
        its patch's net or not boolean (naming the patch).

    Notes
    -----
    Conforming interfaces, seams and poles are merged by the constraint map; a
    non-conforming interface is coupled by a displacement penalty projected onto the finer
    edge's splines (a penalised mortar condition); with bending weights, every interface
    and C0 knot line also by a penalty on the slope jump across it. The factors come from
    the material and the mesh (:mod:`splinedeform.physics.coupling_model`); the mass is
    the patches' own. A trimmed face (``parametric`` or ``intrinsic``) brings the matrices
    and the extension map of :func:`~splinedeform.trim.model_matrices.trimmed_system`,
    and the faces sharing a trim curve are coupled along it by the same penalties
    (:func:`~splinedeform.physics.coupling_curves.curve_penalty`), those sharing a
    stretch of a trim edge along it (:func:`~.trim_edges.edge_penalty`).

    Examples
    --------
    >>> import splinedeform as sd
    >>> left = sd.shapes.plane(size=(0.5, 1.0), cells=(2, 2))
    >>> right = left.with_control_points(left.control_points + [0.5, 0, 0])
    >>> model = sd.BodyModel(sd.Body([left, right]), sd.Material(w10=1, w01=1),
    ...                      boundary="clamped")
    >>> model.n_free
    5
    """

    def __init__(self, body: Body | Sequence[Surface], material: Material,
                 boundary: str | Mapping[tuple[int, str], str] = "free",
                 mass_matrix: str = "consistent", rest: str = "initial",
                 physics: str = "intrinsic",
                 fixed: Sequence[NDArray[np.bool_] | None] | None = None):
        start = time.perf_counter()
        if not isinstance(body, Body):
            body = Body(body)
        check_options(material, mass_matrix, rest, physics)
        system = body_system(body, material, boundary, mass_matrix, rest, physics, fixed)
        self.body = body
        self.patches: tuple[Surface, ...] = body.patches
        self.surface = None            # no single surface: the read-out has the patches
        self.gram_u = self.gram_v = None
        self.material, self.mass_matrix, self.rest, self.physics = (material, mass_matrix,
                                                                    rest, physics)
        self.constraints = system.constraints
        self.formulation = system.formulation
        self._full = system.full
        self._K, self._M = system.reduced
        self._C = None
        self._null: tuple[Array | None] | None = None
        self._finish(start)

    # -- layout ------------------------------------------------------------------------
    def to_full(self, d_free: Array) -> list[Array]:  # type: ignore[override]
        """Per patch the full displacement net ``T d_free``: ``(n_u, n_v, 3)`` (or
        ``(n_u, n_v)`` for a scalar field) each."""
        full = np.asarray(self.constraints.T @ d_free)
        parts = np.split(full, self.constraints.offsets[1:-1], axis=0)
        return [part.reshape(s.shape + np.shape(d_free)[1:])
                for part, s in zip(parts, self.patches)]

    def _rest_net(self) -> Array:
        return np.concatenate([s.control_points.reshape(-1, 3) for s in self.patches])

    @property
    def rigid_modes(self) -> int | None:
        """Dimension of ``null K_r``: from the weights and the constraints where they decide
        it (:func:`splinedeform.physics.plate_body.rigid_count`: with tension one constant
        per part that nothing holds; with bending 0 where a clamped edge holds every part),
        else (a bending body with a free part) counted on the matrices at any size
        (:func:`~splinedeform.solvers.rigid.null_space`: dense ``eigh`` up to 1500 free
        coordinates, shift-invert Lanczos near 0 beyond), whose basis is
        :attr:`rigid_fields`. A connected closed body has 1, the constants, as
        ``Δ_S d = 0`` on a closed surface leaves nothing else; a free flat plate its discrete
        harmonic fields (``physics = "intrinsic"``: ``1, x, y, xy, x² − y², …`` as far as
        the degree reaches; ``parametric`` with ``w11 > 0``: ``1, u, v``). ``None`` (unknown) with no bending in both directions or
        without a clear gap between round-off and the elastic eigenvalues."""
        if self._rigid is None:
            count = rigid_count(self.body, self.material, self.constraints)
            if count is None and self.rigid_fields is not None:
                count = int(self.rigid_fields.shape[1])
            self._rigid = (count,)
        return self._rigid[0]

    @property
    def rigid_fields(self) -> Array | None:
        """An ``M_r``-orthonormal basis ``(n_free, k)`` of ``null K_r`` found on the
        matrices (module docstring of :mod:`splinedeform.solvers.rigid`), or ``None``
        where the weights leave no clear gap; for the fields of every control point,
        :meth:`to_full` of its columns."""
        if self._null is None:
            m = self.material
            try:
                known = known_fields(self.patches, self.constraints)
                self._null = (null_space(self._K, self._M, "the rigid modes of a body",
                                         known) if m.w20 > 0 and m.w02 > 0 else None,)
            except UnresolvedSpectrum:
                self._null = (None,)
        return self._null[0]
