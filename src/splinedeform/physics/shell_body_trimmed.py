"""The Kirchhoff–Love shell on a body with trimmed faces.

As the plate's body (:mod:`.plate_body`), each trimmed face ``p`` brings its own shell
(:func:`~splinedeform.trim.shell_trimmed.trimmed_shell`): ``K_p``, ``M_p`` over its
trimmed region, its held loops (and a holed rectangle's held edges) by Nitsche's terms,
and its map ``d_p = (E_p ⊗ I₃) d_p,free`` with Höllig's extension ``E_p``. The untrimmed
patches are :mod:`.shell_body`'s, the trimmed faces there free and unmerged (their
iso-edge interfaces non-conforming, :func:`~splinedeform.body.trimmed.unmerged_at_trims`),
so that the body's map is ``T = T_untrimmed ⊕ (E_p ⊗ I₃) …`` (:func:`with_face_maps`) and

.. math:: K = \\operatorname{diag}(K_1, …, K_P) + K_\\text{coupling}
          + Σ_Γ \\left(α K_\\text{values} ⊗ I_3 + β K_θ\\right),

the last sum over the trim curves two faces share and the stretches of trim edges they
share (:mod:`splinedeform.body.trimmed`, :mod:`splinedeform.body.trim_edges`): on each,
the displacement penalty ``½ α ∫_Γ |Π (d_a − d_b)|² ds`` on all three components and the
rotation penalty ``½ β ∫_Γ (Π (θ_a − θ_b))² ds``, ``θ = ∂_n d · (τ × n)`` the rotation of
a side's conormal fibre about the common tangent (:func:`~.coupling.shell_rotation_penalty`'s
term, :func:`~.coupling.shell_line_penalty`, which keeps the angle between the faces, so
a crease costs nothing when it turns rigidly; :func:`~.coupling_curves.curve_penalty`,
:func:`~splinedeform.body.trim_edges.edge_penalty`). ``Π`` is the line's trace space
(:func:`~.coupling_curves.curve_line`), and
``(α, β) = C (E t, E t³/12) / ((1 − ν²) h)`` from the material and the element size
``h`` along the curve (:func:`~.coupling.penalty_factors`).

A trimmed face's mask of fixed control points (``fixed`` of
:class:`~splinedeform.physics.shell_model.ShellModel`) is taken by its own map
(:func:`~splinedeform.trim.shell_trimmed.trimmed_shell`, as the plate's face takes it).

The free rigid motions are those in ``range T`` on the control points the regions move
and those a face's mask holds at rest (a trimmed face's dropped functions stay at rest
and are no points of the shell), in each connected part of the body that no Nitsche term
holds (:func:`body_motions`).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components

from ..body.body import Body
from ..body.constraints import boundary_presets
from ..body.trim_edges import edge_penalty, iso_stretches
from ..body.trimmed import edge_boundary, face_boundary, loop_presets, mask_of_face
from ..errors import InputError
from ..trim.model_matrices import held_live, quadrature_of
from ..trim.shell_trimmed import trimmed_shell
from .coupling_curves import curve_penalty
from .shell import ShellMaterial
from .shell_body import BODY_KINDS, ShellBodySystem, body_system
from .shell_rigid import RigidMotions, free_rigid_motions

Array = NDArray[np.float64]


def trimmed_body_system(body: Body, material: ShellMaterial,
                        boundary: str | Mapping[Any, str] = "free",
                        fixed: NDArray[np.bool_] | None = None,
                        face_fixed: Mapping[int, NDArray[np.bool_]] | None = None
                        ) -> ShellBodySystem:
    """The shell of a body with trimmed faces (module docstring).

    ``boundary`` is one kind for every boundary edge and trim loop, or a mapping keyed
    ``(patch, edge)`` and ``(face, loop)`` (``"outer"``, ``"hole1"``, ``"outer.2"`` …) as
    :class:`splinedeform.BodyModel` takes it; a loop or trim edge shared with another face
    takes none (:func:`~splinedeform.body.trimmed.loop_presets`). ``fixed`` holds
    components of the untrimmed patches as :func:`.shell_body.body_system` does;
    ``face_fixed`` (``{face: mask (n_u, n_v)}``,
    :func:`~splinedeform.body.constraints.trimmed_face_masks`) the control points of
    trimmed faces, taken by each face's own map
    (:func:`~splinedeform.trim.shell_trimmed.trimmed_shell`). No control point of a
    trimmed face is merged with another face's (penalties couple them), so a held one is
    held in its face alone.
    """
    patches = body.patches
    faces = sorted(p for p, s in enumerate(patches) if s.trim is not None)
    loops = loop_presets(patches, body.trim_interfaces, boundary, body.edge_interfaces)
    presets = boundary_presets(edge_boundary(boundary, loops), body.topology, BODY_KINDS)
    face_fixed = face_fixed or {}
    shells = {}
    for p in faces:
        with mask_of_face(p):
            shells[p] = trimmed_shell(patches[p], material,
                                      face_boundary(p, patches[p], presets, loops),
                                      face_fixed.get(p))
    system = body_system(body, material, {k: v for k, v in presets.items()
                                          if k[0] not in shells},
                         given={p: (s.stiffness, s.mass) for p, s in shells.items()},
                         fixed=fixed)
    offsets = system.offsets
    K = system.K
    edges = {**presets, **loops}
    for interface in body.trim_interfaces:
        K = K + curve_penalty(patches, interface, material, offsets[:-1])
    iso = iso_stretches(body.edge_interfaces)           # coupled by the shell body already
    for interface in (i for i in body.edge_interfaces if i not in iso):
        K = K + edge_penalty(patches, interface, material, offsets[:-1], edges)
    T = with_face_maps(system.T, offsets, {p: s.T for p, s in shells.items()})
    held = {p for p, s in shells.items() if any(k != "free" for k in s.edges.values())}
    return ShellBodySystem(K.tocsr(), system.M, T, edges, offsets, system.ties, system.clamps,
                           body_motions(body, T, offsets, held, at_rest(body, face_fixed)))


def at_rest(body: Body, face_fixed: Mapping[int, NDArray[np.bool_]]) -> NDArray[np.bool_]:
    """The body's points (flat, patch after patch) that a trimmed face's mask holds and
    whose B-splines meet its region (:func:`~splinedeform.trim.model_matrices.held_live`):
    zero rows of ``T`` that are points of the shell, at rest."""
    parts = [np.zeros(s.shape[0] * s.shape[1], dtype=bool) if p not in face_fixed else
             held_live(s, quadrature_of(s).classes, face_fixed[p]).ravel()
             for p, s in enumerate(body.patches)]
    return np.concatenate(parts)


def with_face_maps(T: sp.csr_matrix, offsets: NDArray[np.int64],
                   maps: Mapping[int, sp.csr_matrix]) -> sp.csr_matrix:
    """``T`` with the columns of each face ``p`` in ``maps`` replaced by ``T_p cols @
    maps[p]``: the face's own map ``E_p ⊗ I₃`` on its ``3 n_p`` rows.

    ``T`` must leave each such face free and unmerged: ``3 n_p`` columns, the unit vectors
    of its rows in order, touching no other row (a trimmed face's iso-edges are coupled by
    penalties, and the shell body merges or ties nothing of it)."""
    T = sp.csc_matrix(T)
    first_row = np.full(T.shape[1], -1, dtype=np.int64)
    counts = np.diff(T.indptr)
    first_row[counts > 0] = T.indices[T.indptr[:-1][counts > 0]]
    owner = np.searchsorted(3 * offsets, first_row, side="right") - 1
    blocks = [T[:, np.flatnonzero(~np.isin(owner, list(maps)))]]
    for p, own in maps.items():
        columns = np.flatnonzero(owner == p)
        rows = np.arange(3 * offsets[p], 3 * offsets[p + 1])
        block = T[:, columns]
        if columns.size != rows.size or block.nnz != rows.size or \
                np.any(block.indices != rows) or not np.allclose(block.data, 1.0, atol=1e-14):
            raise InputError(f"face {p} is trimmed but its control points are merged or tied "
                             "with another face's (a conforming edge of its rectangle, a "
                             "pole); trimmed faces meet along their trim curves and by "
                             "penalties only")
        blocks.append(block @ sp.csr_matrix(own))
    return sp.hstack(blocks, format="csr")


def body_motions(body: Body, T: sp.csr_matrix, offsets: NDArray[np.int64],
                 held: set[int], fixed: NDArray[np.bool_] | None = None) -> RigidMotions:
    """The free rigid motions of the body (module docstring): those in ``range T`` on the
    control points of the connected parts without a face in ``held`` (a face whose loops
    or edges Nitsche's terms hold), a trimmed face's moving ones and its points that its
    mask holds (``fixed``, flat, :func:`at_rest`) only (its dropped functions are no points
    of the shell; an untrimmed patch's held points are, at rest)."""
    n = len(body.patches)
    links = [(i.a, i.b) for i in body.topology.interfaces + body.trim_interfaces
             + body.edge_interfaces] or [(0, 0)]
    graph = sp.coo_matrix((np.ones(len(links)), np.array(links).T), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    free_parts = set(label.tolist()) - {int(label[p]) for p in held}
    points = np.concatenate([s.control_points.reshape(-1, 3) for s in body.patches])
    patch_of = np.searchsorted(offsets, np.arange(len(points)), side="right") - 1
    trimmed = np.array([s.trim is not None for s in body.patches])
    moving = (np.diff(T.indptr)[::3] > 0) | ~trimmed[patch_of]
    if fixed is not None:
        moving |= fixed
    chosen = np.flatnonzero(moving & np.isin(label[patch_of], list(free_parts)))
    if chosen.size == 0:
        return RigidMotions(np.zeros((T.shape[1], 0)), np.zeros((6, 0)))
    rows = (3 * chosen[:, None] + np.arange(3)).ravel()
    part = sp.csc_matrix(T[rows])
    columns = np.flatnonzero(np.diff(part.indptr) > 0)    # the chosen parts' coordinates
    found = free_rigid_motions(part[:, columns], points[chosen])
    reduced = np.zeros((T.shape[1], found.count))
    reduced[columns] = found.reduced
    return RigidMotions(reduced, found.twists)
