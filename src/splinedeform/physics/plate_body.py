"""The thin plate under tension on a body of patches: matrices, couplings, constraint map.

The unknowns are all patches' control points (patch after patch); per patch the matrices
are those of a single surface (:func:`splinedeform.assembly.patch_matrices`, or a trimmed
face's :func:`~splinedeform.trim.model_matrices.trimmed_system`), so that

.. math:: K = \\operatorname{diag}(K_1, …, K_P) + K_\\text{coupling}, \\qquad
          M = \\operatorname{diag}(M_1, …, M_P),

where ``K_coupling`` is the penalty coupling each non-conforming interface and, with
bending, the rotation across every interface and C0 line (:mod:`.coupling_model`), and
the penalty along each trim curve two faces share (:mod:`.coupling_curves`) and along
each stretch of trim edges they share (:mod:`splinedeform.body.trim_edges`). The
constraint map ``d = T d_free`` of :mod:`splinedeform.body.constraints` merges the control
points of conforming interfaces and poles, ties the slopes across smooth ones and applies
the edge conditions of boundary edges: ``K_r = Tᵀ K T``, ``M_r = Tᵀ M T``, ``F_r = Tᵀ F``
(:class:`BodyReduction`). :class:`splinedeform.BodyModel` is the one model on this system,
as :class:`splinedeform.ShellModel` is on :mod:`.shell_body`'s.

The rigid modes (``null K_r``) follow from the weights and the constraints where they can
(:func:`rigid_count`), else from the matrices themselves
(:func:`splinedeform.solvers.rigid.null_space`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial
from typing import Any, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import splu

from ..assembly import check_bending, patch_matrices
from ..body.body import Body
from ..body.constraints import (BodyConstraints, body_fixed_mask, boundary_presets,
                                build_body_constraints, trimmed_face_masks)
from ..body.interface import EDGES
from ..body.loads import OnPatch, along_normal
from ..body.trim_edges import edge_penalty
from ..body.trimmed import (edge_boundary, face_boundary, loop_presets, mask_of_face,
                            with_trimmed_faces)
from ..errors import InputError
from ..loads import Point
from ..material import Material
from ..solvers.system import Reduction
from ..surface import Surface
from ..trim.model_matrices import trimmed_system
from .coupling_curves import curve_penalty
from .coupling_model import bends, c0_coupling, interface_coupling
from .plate import PlateFormulation

Array = NDArray[np.float64]


@dataclass(frozen=True)
class BodyReduction(Reduction):
    """:class:`~splinedeform.solvers.system.Reduction` of a body: a load's vector is the
    patches' vectors, patch after patch; :class:`~splinedeform.body.OnPatch` loads act on
    their patch only. ``signs`` is the body's :attr:`~splinedeform.body.Body.orientation`
    (empty: ``+1`` on every patch): a pressure's vector on patch ``p`` is
    ``signs[p] ∫ q (x_u × x_v) N_k`` (:func:`splinedeform.body.loads.along_normal`)."""

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


@dataclass(frozen=True)
class PlateBodySystem:
    """The plate of a body, assembled (:func:`body_system`): its formulation, constraint
    map, ``(K, M)`` over all patches with their couplings, and ``(K_r, M_r)``."""

    formulation: PlateFormulation
    constraints: BodyConstraints
    full: tuple[sp.csr_matrix, sp.csr_matrix]
    reduced: tuple[sp.csc_matrix, sp.csc_matrix]


def body_system(body: Body, material: Material,
                boundary: str | Mapping[tuple[int, str], str] = "free",
                mass_matrix: str = "consistent", rest: str = "initial",
                physics: str = "intrinsic",
                fixed: Sequence[Any] | None = None) -> PlateBodySystem:
    """Assemble the plate of a body (module docstring; the parameters are
    :class:`splinedeform.BodyModel`'s, the options already checked; ``fixed``, one mask
    per patch, fixes control points: :func:`~splinedeform.body.constraints.body_fixed_mask`
    on the untrimmed patches, a trimmed face's mask
    (:func:`~splinedeform.body.constraints.trimmed_face_masks`) taken by its own map in
    :func:`~splinedeform.trim.model_matrices.trimmed_system`, the face then counted among
    the held ones where it holds a point whose B-spline meets its region).

    Raises
    ------
    InputError
        A non-manifold edge or an interface not parametrised alike (:func:`refuse`), a
        bad mask of fixed points (on a trimmed face also one that leaves its extension no
        array of free inner B-splines, ``fixed[p]: face p is trimmed …``), or a boundary
        that fixes every control point.
    """
    topology = body.topology
    refuse(topology)
    patches = body.patches
    for surface in patches:
        check_bending(surface, material)
    trims = body.trim_interfaces
    faces = {p for p, s in enumerate(patches) if s.trim is not None}
    loops = loop_presets(patches, trims, boundary, body.edge_interfaces)
    presets = boundary_presets(edge_boundary(boundary, loops), topology)
    constraints = build_body_constraints(
        patches, topology, {k: "free" if k[0] in faces else v for k, v in presets.items()},
        bends(material), body_fixed_mask(patches, fixed))
    masks = trimmed_face_masks(patches, fixed)
    systems = {}
    for p in sorted(faces):
        with mask_of_face(p):
            systems[p] = trimmed_system(patches[p], material,
                                        face_boundary(p, patches[p], presets, loops),
                                        mass_matrix == "lumped", physics, masks.get(p), rest)
    if systems:
        held = {p for p, s in systems.items() if s.constraints.has_fixed_points}
        constraints = replace(with_trimmed_faces(
            constraints, patches, {p: s.constraints for p, s in systems.items()}, loops),
            edges={**presets, **loops}, fixed_patches=constraints.fixed_patches | held)
    if constraints.n_free == 0:
        error = InputError(f"no free coordinate: the boundary fixes every control point of "
                           f"the {len(patches)} patches; free an edge or refine them")
        error.key = "boundary"  # type: ignore[attr-defined]
        raise error
    blocks = [(systems[p].stiffness, systems[p].mass) if p in systems
              else patch_matrices(s, material, physics, mass_matrix == "lumped")[2:]
              for p, s in enumerate(patches)]
    K = sp.block_diag([k for k, _ in blocks], format="csr")
    M = sp.block_diag([m for _, m in blocks], format="csr")
    for penalty in couplings(patches, topology, trims, material, constraints,
                             body.edge_interfaces):
        K = (K + penalty).tocsr()
    formulation = PlateFormulation(physics, material, patches=patches,
                                   reduction_type=partial(BodyReduction,
                                                          signs=body.orientation),
                                   unconstrained=constraints.unconstrained)
    T = constraints.T
    return PlateBodySystem(formulation, constraints, (K, M),
                           ((T.T @ K @ T).tocsc(), (T.T @ M @ T).tocsc()))


def couplings(patches: Sequence[Surface], topology: Any, trims: Sequence[Any],
              material: Material, constraints: BodyConstraints,
              stretches: Sequence[Any] = ()) -> list[sp.spmatrix]:
    """The penalties of ``K_coupling`` (module docstring): across the interfaces, along the
    shared trim curves and the shared stretches of trim edges (``stretches``,
    :func:`~splinedeform.body.trim_edges.edge_penalty`) and across each patch's C0 lines,
    leaving out the slopes that the constraint map ties exactly (``constraints.ties``)."""
    offsets = constraints.offsets
    size = int(offsets[-1])
    ties = constraints.ties
    terms = [interface_coupling(patches, topology.interfaces, material, constraints.edges,
                                offsets[:-1], ties.interfaces)]
    terms += [curve_penalty(patches, i, material, offsets[:-1]) for i in trims]
    terms += [edge_penalty(patches, i, material, offsets[:-1], constraints.edges)
              for i in stretches]
    terms += [c0_coupling(s, material, {e: constraints.edges.get((p, e), "free")
                                        for e in EDGES}, int(offsets[p]), size,
                          {(d, k) for q, d, k in ties.lines if q == p})
              for p, s in enumerate(patches)]
    return [t for t in terms if t is not None]


def rigid_count(body: Body, material: Material, constraints: BodyConstraints) -> int | None:
    """``dim null K_r`` where the weights and the constraints decide it, else ``None``.

    With tension in both directions (``w10, w01 > 0``) the energy vanishes on constant
    displacements only: one per connected part of the body that no pinned or clamped edge
    and no fixed control point holds. Without tension but with bending in both directions
    (``w20, w02 > 0``) it is 0
    where a clamped edge holds every part: a field without energy is a polynomial with
    ``d_uu = d_vv = 0`` (``Δ d = 0`` intrinsic) on each span, which vanishes with its value
    and slope on a segment (unique continuation), and the merged points, the ties and the
    penalties carry value and slope across every span border and interface. ``None``
    where it depends on the geometry (a bending body with a free part: count it on the
    matrices) or no weight bends in both directions (``-1`` is never returned).
    """
    m = material
    if m.w10 > 0 and m.w01 > 0:
        holds = ("pinned", "clamped")
    elif m.w20 > 0 and m.w02 > 0:
        holds = ("clamped",)
    else:
        return None
    n = len(body.patches)
    links = [(i.a, i.b) for i in body.topology.interfaces + body.trim_interfaces
             + body.edge_interfaces] or [(0, 0)]
    graph = sp.coo_matrix((np.ones(len(links)), np.array(links).T), shape=(n, n))
    parts, label = connected_components(graph, directed=False)
    held = np.zeros(parts, dtype=bool)
    for (p, _), preset in constraints.edges.items():
        held[label[p]] |= preset in holds
    if holds == ("pinned", "clamped"):
        held[label[list(constraints.fixed_patches)]] = True
        return int(np.sum(~held))
    return 0 if held.all() else None


def known_fields(patches: Sequence[Surface], constraints: BodyConstraints) -> Array:
    """The fields of zero energy that every plate may have, where the constraint map admits
    them: ``(n_free, c)`` coordinates ``z`` with ``T z = f`` for ``f`` among the constant
    ``1`` (a translation, for each coordinate) and the coordinate fields ``x, y, z`` of the
    initial surface (their coefficients are the control points, the geometry being in the
    patches' own basis; harmonic on a flat face, so without bending energy there). The
    model keeps only what ``K_r`` annihilates (:func:`splinedeform.solvers.rigid.null_space`).
    """
    points = np.concatenate([s.control_points.reshape(-1, 3) for s in patches])
    fields = np.column_stack([np.ones(len(points)), points - points.mean(axis=0)])
    T = sp.csc_matrix(constraints.T)
    z = splu(sp.csc_matrix(T.T @ T)).solve(np.asarray(T.T @ fields))
    miss = np.linalg.norm(np.asarray(T @ z) - fields, axis=0)
    return z[:, miss <= 1e-9 * np.maximum(np.linalg.norm(fields, axis=0), 1e-300)]


def refuse(topology: Any) -> None:
    """Refuse what neither the constraint map nor a penalty couples: a non-manifold edge
    (three or more patch edges on one curve), an interface whose two edges are not
    parametrised alike along the curve (not an affine map of each other)."""
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
