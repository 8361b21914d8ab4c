"""Trimmed faces in a body: their edges, the trim curves they share, their constraint maps.

A trimmed face (``surface.trim``) bounds its region by trim loops. Its rectangle's edges
belong to the region only when its outer loop is the rectangle itself (a rectangle with
holes, :func:`~splinedeform.trim.surface_trim.holed_rectangle`); otherwise they lie outside
it and take no part in the iso-edge topology (:func:`without_trimmed_edges`). Two faces
meet along a trim curve where a loop of one and a loop of the other trace the same curve
in space (:func:`find_trim_interfaces`): every sample of each within the body's tolerance of
the other, found by closest-point projection
(:meth:`~splinedeform.physics.coupling_curves.CurveSide.closest`). Such a
:class:`~.interface.TrimInterface` is coupled by the penalties along the curve
(:func:`~splinedeform.physics.coupling_curves.curve_penalty`).

Each trimmed face's matrices and map ``d_p = E_p d_p,free`` (Höllig's extension, Nitsche's
terms for held loops) are those of :func:`~splinedeform.trim.model_matrices.trimmed_system`;
the body's map is ``T = T_untrimmed ⊕ E_p …`` (:func:`with_trimmed_faces`).
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import replace
from typing import Any, Iterator, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..surface import Surface
from ..trim.model_matrices import loop_names
from ..trim.surface_trim import holed_rectangle
from .constraints import BodyConstraints
from .interface import TrimInterface
from .topology import Edge, Topology

Array = NDArray[np.float64]
LOOP_SAMPLES = 24
"""Samples per loop compared with the other loop's curve when looking for shared curves."""


def trimmed(surface: Surface) -> bool:
    """Whether a face is trimmed."""
    return surface.trim is not None


def edgeless(surface: Surface) -> bool:
    """Whether a face's rectangle edges lie outside its region (trimmed, not a rectangle
    with holes)."""
    return trimmed(surface) and not holed_rectangle(surface)


def without_trimmed_edges(patches: Sequence[Surface], topology: Topology) -> Topology:
    """``topology`` without the rectangle edges of :func:`edgeless` faces: their interfaces
    are dropped (the other face's edge becomes a boundary edge), and so are their boundary
    edges and poles."""
    gone = {p for p, s in enumerate(patches) if edgeless(s)}
    if not gone:
        return topology
    keep = [k for k, i in enumerate(topology.interfaces) if not {i.a, i.b} & gone]
    freed = [edge for i in topology.interfaces for edge in ((i.a, i.edge_a), (i.b, i.edge_b))
             if {i.a, i.b} & gone and edge[0] not in gone]
    boundary = [e for e in topology.boundary if e[0] not in gone] + freed
    groups = tuple(g for g in (tuple(e for e in group if e[0] not in gone)
                               for group in topology.non_manifold) if len(g) > 2)
    return Topology(tuple(topology.interfaces[k] for k in keep),
                    tuple(topology.aligned[k] for k in keep), tuple(dict.fromkeys(boundary)),
                    tuple(e for e in topology.poles if e[0] not in gone), groups,
                    topology.tol)


def unmerged_at_trims(patches: Sequence[Surface], topology: Topology) -> Topology:
    """``topology`` with every interface of a trimmed face (an iso-edge of a rectangle with
    holes) marked non-conforming, so that it is coupled by penalties: a trimmed face's
    control points follow its own extension map and are merged with no other face's."""
    faces = {p for p, s in enumerate(patches) if trimmed(s)}
    turned = tuple(replace(i, conforming=False) if {i.a, i.b} & faces else i
                   for i in topology.interfaces)
    return replace(topology, interfaces=turned)


def curve_loops(surface: Surface) -> list[int]:
    """Indices of a face's trim loops that are curves of its region's boundary (all but
    the rectangle of a rectangle with holes)."""
    if not trimmed(surface):
        return []
    first = 1 if holed_rectangle(surface) else 0
    return list(range(first, len(surface.trim.loops)))


def find_trim_interfaces(patches: Sequence[Surface], tol: float) -> tuple[TrimInterface, ...]:
    """Pairs of trim loops of two faces that trace one curve (module docstring), each loop
    in at most one pair."""
    from ..physics.coupling_curves import CurveSide, curve_breaks, period

    sides = {(p, k): CurveSide.of_loop(s, s.trim.loops[k])
             for p, s in enumerate(patches) for k in curve_loops(s)}
    samples = {}
    for key, side in sides.items():
        t = np.linspace(0.0, period(side.loop), LOOP_SAMPLES, endpoint=False)
        samples[key] = side.position(t)[0]
        curve_breaks(side.loop, *_lengths(side.surface))          # the loop fits the grid
    used: set[tuple[int, int]] = set()
    found = []
    keys = list(sides)
    for i, first in enumerate(keys):
        for second in keys[i + 1:]:
            if first[0] == second[0] or first in used or second in used:
                continue
            a, b = samples[first], samples[second]
            scale = max(np.ptp(a, axis=0).max(), np.ptp(b, axis=0).max())
            if _nearest(a, b) > 10 * tol + 0.5 * scale:     # far apart: no projection
                continue
            gap_ab = np.linalg.norm(sides[second].position(sides[second].closest(a))[0] - a,
                                    axis=1).max()
            gap_ba = np.linalg.norm(sides[first].position(sides[first].closest(b))[0] - b,
                                    axis=1).max()
            if max(gap_ab, gap_ba) <= tol:
                found.append(TrimInterface(first[0], first[1], second[0], second[1]))
                used |= {first, second}
    return tuple(found)


def checked_trim_interfaces(patches: Sequence[Surface], given: Sequence[Any]
                            ) -> tuple[TrimInterface, ...]:
    """``given`` if each is a :class:`~.interface.TrimInterface` naming a curve loop
    (:func:`curve_loops`) of two different faces, each loop in one interface at most."""
    seen: set[tuple[int, int]] = set()
    for i in given:
        if not isinstance(i, TrimInterface):
            raise InputError(f"trim interfaces must be splinedeform.body.TrimInterface "
                             f"records, got {type(i).__name__}")
        if i.a == i.b:
            raise InputError(f"{i}: a trim interface joins two different faces")
        for p, k in ((i.a, i.loop_a), (i.b, i.loop_b)):
            if not 0 <= p < len(patches) or k not in curve_loops(patches[p]):
                raise InputError(f"{i}: face {p} has no trim loop {k} bounding its region "
                                 f"(the body has {len(patches)} faces)")
            if (p, k) in seen:
                raise InputError(f"{i}: loop {k} of face {p} is in two trim interfaces")
            seen.add((p, k))
    return tuple(given)


def _lengths(surface: Surface) -> tuple[tuple[float, float], tuple[int, int]]:
    (_, lu), (_, lv) = surface.domain
    return (lu, lv), (surface.basis_u.cells, surface.basis_v.cells)


def _nearest(a: Array, b: Array) -> float:
    """Largest distance of a sample of ``a`` to the nearest sample of ``b``."""
    return float(np.sqrt(((a[:, None] - b[None]) ** 2).sum(-1).min(axis=1)).max())


def loop_presets(patches: Sequence[Surface], interfaces: Sequence[TrimInterface],
                 boundary: str | Mapping[Any, str],
                 edge_interfaces: Sequence[Any] = ()) -> dict[Edge, str]:
    """The preset of every trim loop of a trimmed face, keyed ``(face, loop name)``
    (``outer``, ``hole1`` …), and of its trim edges named in ``boundary`` or shared,
    keyed ``(face, "outer.2")``: ``free`` where the loop is a trim interface or the edge
    is shared with another face (:class:`~.interface.TrimEdgeInterface`, in whole or in
    part), else the body's preset name or ``boundary[key]`` (an edge missing there takes
    its loop's, a loop missing there is free)."""
    shared = {(i.a, i.loop_a) for i in interfaces} | {(i.b, i.loop_b) for i in interfaces}
    edges = {(i.a, i.edge_a) for i in edge_interfaces} | {(i.b, i.edge_b) for i in
                                                           edge_interfaces}
    given = {} if isinstance(boundary, str) else boundary
    out: dict[Edge, str] = {}
    for p, surface in enumerate(patches):
        names = loop_names(surface.trim) if trimmed(surface) else ()
        for k in curve_loops(surface):
            key = (p, names[k])
            count = surface.trim.edge_count(k)
            keys = [key] + [(p, f"{names[k]}.{e}") for e in range(count) if count > 1]
            for one in keys:
                if ((p, k) in shared or one in edges) and one in given:
                    raise InputError(f"boundary[{one!r}]: {one[1]} of face {p} is shared with "
                                     "another face, not a boundary loop or edge")
            if (p, k) in shared or key in edges:
                out[key] = "free"
                continue
            out[key] = boundary if isinstance(boundary, str) else given.get(key, "free")
            for one in keys[1:]:
                if one in edges:
                    out[one] = "free"
                elif one in given:
                    out[one] = given[one]
    return out


def edge_boundary(boundary: str | Mapping[Any, str], loops: Mapping[Edge, str]
                  ) -> str | dict[Any, str]:
    """``boundary`` without the loops' keys (what the iso-edge presets take)."""
    if isinstance(boundary, str) or not isinstance(boundary, Mapping):
        return boundary  # type: ignore[return-value]
    return {key: value for key, value in boundary.items() if key not in loops}


def face_boundary(p: int, surface: Surface, edges: Mapping[Edge, str],
                  loops: Mapping[Edge, str]) -> dict[str, str]:
    """The mapping :func:`~splinedeform.trim.model_matrices.trimmed_system` takes for face
    ``p``: its rectangle's edges (a rectangle with holes) and its loops."""
    own = {name: preset for (q, name), preset in loops.items() if q == p}
    if holed_rectangle(surface):
        own.update({e: preset for (q, e), preset in edges.items() if q == p})
    return own


def with_trimmed_faces(constraints: BodyConstraints, patches: Sequence[Surface],
                       maps: Mapping[int, Any], loops: Mapping[Edge, str]) -> BodyConstraints:
    """The body's map with each trimmed face's block replaced by its own map ``E_p``.

    ``constraints`` must leave every trimmed face free and unmerged (its columns one per
    control point, in order); ``maps[p]`` is face ``p``'s
    :class:`~splinedeform.boundary.Constraints` from ``trimmed_system``.
    """
    offsets = constraints.offsets
    T = constraints.T.tocsc()
    owner = np.searchsorted(offsets, constraints.free_index, side="right") - 1
    keep = np.flatnonzero(~np.isin(owner, list(maps)))
    blocks, first = [T[:, keep]], [constraints.free_index[keep]]
    for p, own in maps.items():
        columns = np.flatnonzero(owner == p)
        rows = constraints.free_index[columns] - offsets[p]
        if columns.size != patches[p].shape[0] * patches[p].shape[1] or \
                np.any(rows != np.arange(columns.size)):
            raise InputError(f"face {p} is trimmed but meets another face along an edge of "
                             "its rectangle; trimmed faces meet along their trim curves only")
        blocks.append(T[:, columns] @ own.T)
        first.append(offsets[p] + own.free_index)
    edges = {**constraints.edges, **loops}
    return replace(constraints, T=sp.hstack(blocks, format="csr"),
                   free_index=np.concatenate(first).astype(np.int64), edges=edges)


@contextmanager
def mask_of_face(p: int) -> Iterator[None]:
    """Re-raise an :class:`~splinedeform.errors.InputError` that face ``p``'s mask of fixed
    control points causes (marked ``fixed_points`` by
    :func:`~splinedeform.trim.model_matrices.trimmed_system`) as ``fixed[p]: face p …``,
    with ``patch = p`` for a scenario to name its key."""
    try:
        yield
    except InputError as exc:
        if not getattr(exc, "fixed_points", False):
            raise
        error = InputError(f"fixed[{p}]: face {p} is trimmed and its mask of fixed control "
                           f"points cannot be taken: {exc}")
        error.patch = p  # type: ignore[attr-defined]
        raise error from None
