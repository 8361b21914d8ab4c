"""Loose trimmed faces of a CAD file joined to the others where their trim edges meet.

A trimmed face is **loose** when the file joins it to nothing: each of its edges it alone
uses, once (:func:`loose_trimmed`), as exporters write every face as its own trimmed
surface with no shared edges. Its loops are read from the file's listing
(:func:`splinedeform.cad_trims.domain_from_arrays`) and its trim edges matched by the
body's own geometric matching, within the body's tolerance (``1e-6`` of the bounding-box
diagonal, :func:`splinedeform.body.topology.find_topology`), exactly as a body of trimmed
faces couples them (:class:`splinedeform.body.Body`):

* two loops that trace one curve: a :class:`~splinedeform.body.interface.TrimInterface`
  (:func:`splinedeform.body.trimmed.find_trim_interfaces`), coupled along the whole curve;
* a trim edge along another face's trim edge, or along a side of an untrimmed face that
  no interface takes, in whole or in part: a
  :class:`~splinedeform.body.interface.TrimEdgeInterface` stretch
  (:func:`splinedeform.body.trim_edges.find_edge_interfaces`).

Only the joins with a loose trimmed face on one side are added (a face the file joins
keeps the file's word). The joins are counted as the file would count the same faces
sewn (one edge of two uses for each pair of edges joined), so that a loose file's counts
equal those of its sewn twin: with ``P`` the pairs joined, ``C`` the edges they couple
(each once) and ``O`` those of ``C`` that lie on no side of their face's rectangle (off
sides, as :func:`splinedeform.cad_topology.body_topology` places the file's edges),
``shared += |P|``, ``boundary −= |C|``, ``off_sides += |P_O| − |O|`` and
``trim_edges.shared += |P_O|``, ``trim_edges.free −= |O|``, ``P_O`` the pairs with an edge
in ``O``; ``joined_by_geometry += |P|`` and, for the pairs that do not run along the
whole of both edges (stretches), ``partly_shared`` and ``partly_joined_by_geometry``.
Where a stretch covers part of an edge, a sewn file has that edge split at the stretch's
ends (the shared piece and the free ones, each an edge); here it stays one edge, coupled
along the stretch, so ``boundary`` lacks the free pieces.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Collection, Sequence

import numpy as np

from .body.interface import EDGES
from .body.topology import find_topology
from .body.trim_edges import edge_curve, find_edge_interfaces, labelled, side
from .body.trimmed import find_trim_interfaces, without_trimmed_edges
from .cad import NurbsPatch
from .cad_3dm_read import TRIM_TOL
from .cad_topology import Topology, _size, place_on_side, side_curves
from .errors import InputError
from .trim.model_matrices import loop_names

#: fraction of an edge's length by which a stretch may fall short of it and still be whole
WHOLE_EDGE = 1e-6
#: points of a trim edge tested against its face's sides (at the middles of equal pieces)
EDGE_POINTS = 9

Join = tuple[int, str, int, str, bool]


def loose_trimmed(listing: dict[str, Any], kept: Sequence[int],
                  trimmed: Collection[int]) -> set[int]:
    """The body's patches (indices into ``kept``) whose file faces are among the trimmed
    file faces ``trimmed`` and share no edge of the file with a face (or with themselves)."""
    joined = {f for edge in listing["edges"] if len(edge["faces"]) > 1 for f in edge["faces"]}
    return {k for k, face in enumerate(kept) if face in trimmed and face not in joined}


def trimmed_patches(surfaces: Sequence[Any], listing: dict[str, Any], kept: Sequence[int],
                    trimmed: Collection[int]) -> list[Any]:
    """``surfaces`` with each trimmed face's loops attached from the listing (its trim edges
    named, :func:`~splinedeform.body.trim_edges.labelled`); a face whose loops cannot be
    read or held is left untrimmed."""
    from .cad_trims import domain_from_arrays

    out = list(surfaces)
    for k, face in enumerate(kept):
        data = listing["faces"][face].get("trim")
        if face not in trimmed or not data:
            continue
        try:
            domain = domain_from_arrays(data, f"face {face}")
            if domain is not None:
                out[k] = labelled(surfaces[k].with_trim(domain))
        except InputError:
            continue
    return out


def join_trims(surfaces: Sequence[Any], listing: dict[str, Any], kept: Sequence[int],
               trimmed: Collection[int], topology: Topology) -> Topology:
    """``topology`` with the joins of the body's loose trimmed faces (module docstring):
    ``surfaces`` the body's faces (untrimmed), file face ``kept[k]`` the ``k``-th,
    ``trimmed`` the file face numbers of the trimmed ones."""
    from .cad_body import patches_of

    loose = loose_trimmed(listing, kept, trimmed)
    if not loose:
        return topology
    patches = patches_of(listing)
    return join_loose_trims(trimmed_patches(surfaces, listing, kept, trimmed),
                            [patches[f] for f in kept], topology, loose)


def join_loose_trims(surfaces: Sequence[Any], patches: Sequence[NurbsPatch],
                     topology: Topology, loose: set[int]) -> Topology:
    """``topology`` with the joins of the ``loose`` trimmed faces among ``surfaces``
    (attached trims, :func:`trimmed_patches`; ``patches`` the same faces as the file's
    NURBS patches) found from the geometry and counted (module docstring), listed in
    :attr:`~splinedeform.cad_topology.Topology.trim_joins` as
    ``(a, edge_a, b, edge_b, whole)``: an edge a trim loop's name (``hole1``), a trim
    edge's (``outer.2``) or a side (``u0``)."""
    loose = {p for p in loose if surfaces[p].trim is not None}
    if not loose:
        return topology
    found = without_trimmed_edges(surfaces, find_topology(surfaces))
    tol = found.tol
    whole = [i for i in find_trim_interfaces(surfaces, tol) if {i.a, i.b} & loose]
    shared_loops = {(i.a, i.loop_a) for i in whole} | {(i.b, i.loop_b) for i in whole}
    taken = {(i.a, i.edge_a) for i in topology.interfaces} | {
        (i.b, i.edge_b) for i in topology.interfaces}
    taken |= {s for a, ea, b, eb in topology.stretches for s in ((a, ea), (b, eb))}
    free = [s for s in found.boundary if s not in taken and surfaces[s[0]].trim is None]
    parts = [i for i in find_edge_interfaces(surfaces, free, shared_loops, tol)
             if {i.a, i.b} & loose and not (i.edge_a in EDGES and i.edge_b in EDGES)]
    joins: list[Join] = [(i.a, loop_names(surfaces[i.a].trim)[i.loop_a], i.b,
                          loop_names(surfaces[i.b].trim)[i.loop_b], True) for i in whole]
    joins += list(dict.fromkeys((i.a, i.edge_a, i.b, i.edge_b, _whole(surfaces, i))
                                for i in parts))
    counts = dict(topology.counts)
    counts["joined_by_geometry"] = counts.get("joined_by_geometry", 0) + len(joins)
    if not joins:
        return replace(topology, counts=counts)
    coupled = list(dict.fromkeys(s for a, ea, b, eb, _ in joins for s in ((a, ea), (b, eb))))
    off = {s for s in coupled if _off_sides(surfaces, patches, *s)}
    off_pairs = sum(bool({(a, ea), (b, eb)} & off) for a, ea, b, eb, _ in joins)
    partly = sum(not w for *_, w in joins)
    counts["shared"] += len(joins)
    counts["boundary"] -= len(coupled)
    counts["off_sides"] += off_pairs - len(off)
    if partly:
        counts["partly_shared"] = counts.get("partly_shared", 0) + partly
        counts["partly_joined_by_geometry"] = (counts.get("partly_joined_by_geometry", 0)
                                               + partly)
    trims = dict(topology.trim_edges)
    trims["shared"] += off_pairs
    trims["free"] -= len(off)
    return replace(topology, counts=counts, trim_edges=trims, trim_joins=joins)


def _whole(surfaces: Sequence[Any], interface: Any) -> bool:
    """Whether a stretch runs along the whole of both its edges (within
    :data:`WHOLE_EDGE` of each edge's parameter length)."""
    for face, name, part in ((interface.a, interface.edge_a, interface.part_a),
                             (interface.b, interface.edge_b, interface.part_b)):
        lo, hi = edge_curve(surfaces, face, name).part
        if abs(min(part) - lo) + abs(max(part) - hi) > WHOLE_EDGE * (hi - lo):
            return False
    return True


def _off_sides(surfaces: Sequence[Any], patches: Sequence[NurbsPatch], face: int,
               name: str) -> bool:
    """Whether edge ``name`` of face ``face`` lies on no side of the face's rectangle, as
    :func:`~splinedeform.cad_topology.body_topology` places a file edge: its points at the
    middles of :data:`EDGE_POINTS` equal pieces within
    :data:`~splinedeform.cad_3dm_read.TRIM_TOL` of the face's size of one side."""
    if name in EDGES:
        return False
    curve = edge_curve(surfaces, face, name)
    lo, hi = curve.part
    t = lo + (hi - lo) * (np.arange(EDGE_POINTS) + 0.5) / EDGE_POINTS
    points = side(surfaces, curve, curve.part).position(t)[0]
    tol = TRIM_TOL * _size(patches[face])
    return not any(place_on_side(c, points)[0].max() <= tol
                   for c in side_curves(patches[face]).values())

