"""A body of patches deformed as one model: one energy, one constraint map, one solve.

The unknowns are all patches' control points (patch after patch); per patch the matrices
are those of a single surface (:func:`splinedeform.assembly.patch_matrices`), so that

.. math:: K = \\operatorname{diag}(K_1, …, K_P), \\qquad M = \\operatorname{diag}(M_1, …, M_P),

plus the penalties coupling non-conforming interfaces and, with bending, the rotation
across every interface and C0 line (:mod:`splinedeform.physics.coupling_model`); the
constraint map ``d = T d_free`` of :mod:`.constraints` merges the control points of
conforming interfaces and poles and applies the edge conditions of boundary edges:
``K_r = Tᵀ K T``, ``M_r = Tᵀ M T``, ``F_r = Tᵀ F``. Everything a solver or a solution needs
(static, modes, the closed-form and numerical dynamics) is the single-surface model's
(:class:`splinedeform.Model`), on these matrices.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from functools import partial
from typing import Any, Mapping, Sequence

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components

from ..assembly import check_bending, patch_matrices
from ..errors import InputError
from ..loads import Point
from ..material import Material
from ..model import Model, check_options
from ..solvers.rigid import UnresolvedSpectrum, count_by_gap
from ..solvers.system import Reduction
from ..surface import Surface
from ..physics.coupling_curves import curve_penalty
from ..physics.coupling_model import bends, c0_coupling, interface_coupling
from ..physics.plate import PlateFormulation
from ..trim.model_matrices import trimmed_system
from .body import Body
from .constraints import boundary_presets, build_body_constraints
from .interface import EDGES
from .loads import OnPatch, along_normal
from .trimmed import edge_boundary, face_boundary, loop_presets, with_trimmed_faces

Array = NDArray[np.float64]
PROBE_LIMIT = 1500
"""Most free coordinates whose rigid modes a bending body without a clamped part counts on
its dense spectrum (:attr:`BodyModel.rigid_modes`): a few seconds of ``eigh``."""


@dataclass(frozen=True)
class BodyReduction(Reduction):
    """:class:`~splinedeform.solvers.system.Reduction` of a body: a load's vector is the
    patches' vectors, patch after patch; :class:`.OnPatch` loads act on their patch only.
    ``signs`` is the body's :attr:`~.Body.orientation` (empty: ``+1`` on every patch): a
    pressure's vector on patch ``p`` is ``signs[p] ∫ q (x_u × x_v) N_k``
    (:func:`.loads.along_normal`)."""

    signs: tuple[int, ...] = ()

    def field(self, term: Any, t: float = 0.0) -> Array:
        parts = []
        turned = along_normal(term)
        for p, surface in enumerate(self.surface):
            if isinstance(term, OnPatch):
                part = (term.load.field_vector(surface, t) if term.patch == p
                        else np.zeros((surface.shape[0] * surface.shape[1], 3)))
            elif isinstance(term, Point):
                raise InputError("a point load on a body needs its patch: "
                                 "splinedeform.body.OnPatch(Point(u, v, force), patch=i)")
            else:
                part = term.field_vector(surface, t)
            parts.append(-part if turned and self.signs and self.signs[p] < 0 else part)
        return np.concatenate(parts)


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
        two edges are parametrised differently along the curve (not an affine map).

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
    (:func:`~splinedeform.physics.coupling_curves.curve_penalty`).

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
                 physics: str = "intrinsic"):
        start = time.perf_counter()
        if not isinstance(body, Body):
            body = Body(body)
        check_options(material, mass_matrix, rest, physics)
        topology = body.topology
        _refuse(topology)
        self.body = body
        self.patches: tuple[Surface, ...] = body.patches
        self.surface = None            # no single surface: the read-out has the patches
        self.gram_u = self.gram_v = None
        self.material, self.mass_matrix, self.rest, self.physics = (material, mass_matrix,
                                                                    rest, physics)
        for surface in self.patches:
            check_bending(surface, material)
        trims = body.trim_interfaces
        faces = {p for p, s in enumerate(self.patches) if s.trim is not None}
        loops = loop_presets(self.patches, trims, boundary)
        presets = boundary_presets(edge_boundary(boundary, loops), topology)
        self.constraints = build_body_constraints(
            self.patches, topology, {k: "free" if k[0] in faces else v
                                     for k, v in presets.items()}, bends(material))
        systems = {p: trimmed_system(self.patches[p], material,
                                     face_boundary(p, self.patches[p], presets, loops),
                                     mass_matrix == "lumped", physics, rest=rest)
                   for p in sorted(faces)}
        if systems:
            self.constraints = replace(with_trimmed_faces(
                self.constraints, self.patches, {p: s.constraints for p, s in systems.items()},
                loops), edges={**presets, **loops})
        if self.constraints.n_free == 0:
            error = InputError(f"no free coordinate: the boundary fixes every control point of "
                               f"the {len(self.patches)} patches; free an edge or refine them")
            error.key = "boundary"  # type: ignore[attr-defined]
            raise error
        blocks = [(systems[p].stiffness, systems[p].mass) if p in systems
                  else patch_matrices(s, material, physics, mass_matrix == "lumped")[2:]
                  for p, s in enumerate(self.patches)]
        K = sp.block_diag([k for k, _ in blocks], format="csr")
        M = sp.block_diag([m for _, m in blocks], format="csr")
        offsets = self.constraints.offsets
        size = int(offsets[-1])
        ties = self.constraints.ties
        couplings = [interface_coupling(self.patches, topology.interfaces, material,
                                        self.constraints.edges, offsets[:-1], ties.interfaces)]
        couplings += [curve_penalty(self.patches, i, material, offsets[:-1]) for i in trims]
        couplings += [c0_coupling(s, material, {e: self.constraints.edges.get((p, e), "free")
                                                for e in EDGES}, int(offsets[p]), size,
                                  {(d, k) for q, d, k in ties.lines if q == p})
                      for p, s in enumerate(self.patches)]
        for penalty in (c for c in couplings if c is not None):
            K = (K + penalty).tocsr()
        reduction = partial(BodyReduction, signs=body.orientation)
        self.formulation = PlateFormulation(physics, material, patches=self.patches,
                                            reduction_type=reduction,
                                            unconstrained=self.constraints.unconstrained)
        self._full = (K, M)
        T = self.constraints.T
        self._K = (T.T @ K @ T).tocsc()
        self._M = (T.T @ M @ T).tocsc()
        self._C = None
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
        """Dimension of ``null K_r``: with tension in both directions the energy vanishes on
        constant displacements only, one per connected part of the body that no pinned or
        clamped edge holds. Without tension but with bending in both directions
        (``w20, w02 > 0``) it is 0 where a clamped edge holds every part: a field without
        energy is a polynomial with ``d_uu = d_vv = 0`` (``Δ d = 0`` intrinsic) on each span,
        which vanishes with its value and slope on a segment (unique continuation), and the
        merged points, the ties and the penalties carry value and slope across every span
        border and interface. Otherwise (a bending body with a free part) it is counted on
        the matrices themselves, up to :data:`PROBE_LIMIT` free coordinates: the
        eigenvalues of ``K_r φ = λ M_r φ`` at round-off level behind a clear gap
        (:func:`~splinedeform.solvers.rigid.count_by_gap`; a connected closed body: 1, the
        constants, as ``Δ_S d = 0`` on a closed surface leaves nothing else; a free flat
        plate: the fields linear in ``x, y``). ``None`` (unknown) beyond that size, with
        no bending in both directions, or without a clear gap."""
        if self._rigid is None:
            self._rigid = (self._rigid_count(),)
        return self._rigid[0]

    def _rigid_count(self) -> int | None:
        m = self.material
        if m.w10 > 0 and m.w01 > 0:
            holds = ("pinned", "clamped")
        elif m.w20 > 0 and m.w02 > 0:
            holds = ("clamped",)
        else:
            return None
        n = len(self.patches)
        links = [(i.a, i.b) for i in self.body.topology.interfaces + self.body.trim_interfaces
                 ] or [(0, 0)]
        graph = sp.coo_matrix((np.ones(len(links)), np.array(links).T), shape=(n, n))
        parts, label = connected_components(graph, directed=False)
        held = np.zeros(parts, dtype=bool)
        for (p, _), preset in self.constraints.edges.items():
            held[label[p]] |= preset in holds
        if holds == ("pinned", "clamped"):
            return int(np.sum(~held))
        if held.all():
            return 0
        if self.n_free > PROBE_LIMIT:
            return None
        lam = sla.eigh(self._K.toarray(), self._M.toarray(), eigvals_only=True,
                       check_finite=False)
        try:
            return count_by_gap(lam, "the rigid modes of a free bending body")
        except UnresolvedSpectrum:
            return None


def _refuse(topology: Any) -> None:
    """Refuse what neither the constraint map nor a penalty couples (see :class:`BodyModel`)."""
    if topology.non_manifold:
        group = topology.non_manifold[0]
        names = ", ".join(f"patch {p} edge {e}" for p, e in group)
        raise InputError(f"non-manifold edge: {len(group)} patch edges meet on one curve "
                         f"({names}); a body's edge joins at most two patch edges")
    for i, aligned in zip(topology.interfaces, topology.aligned):
        if not aligned:
            raise InputError(f"interface between patch {i.a} edge {i.edge_a} and patch {i.b} "
                             f"edge {i.edge_b}: the edges meet, but their parametrisations "
                             "along the curve are not an affine map of each other, which the "
                             "coupling follows; reparametrise one of the two patches")
