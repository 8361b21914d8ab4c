"""Loose faces of a CAD file joined to the others where their sides meet.

A face is **loose** when the file joins it to nothing: a plain NURBS surface of a
``.3dm`` (no edges at all), or an untrimmed face each of whose edges it alone uses, once
(a STEP or IGES face written with its own edges and sewn to no other, as exporters write
an "open shell" of separate ``ADVANCED_FACE``\\ s; a Brep of one face). A loose face's own
edges are its rectangle's sides and carry no join, so they are left out of the file's
topology (:func:`file_edges`) and the face is treated as a plain surface. The other
faces' edges come from the file (:func:`splinedeform.cad_topology.body_topology`).

Where a loose face's side meets a side of another face, of another loose face or of
itself (a seam), it is found from the geometry, as a body of plain patches finds it
(:func:`splinedeform.body.topology.find_topology`: the sides sampled and matched within
``1e-6`` of the body's bounding-box diagonal). Only the sides that the file leaves
unjoined take part: a Brep's boundary edge (one face uses it) can meet a loose face, two
faces that the file joins elsewhere and not to each other are not joined here. A side
that shares only a stretch of its length with another (a T-junction) gets no interface:
the body couples it along the stretch (:mod:`splinedeform.body.trim_edges`, found here by
the same :func:`~splinedeform.body.trim_edges.find_edge_interfaces` to be counted).

The counts then say which edges came from which: ``shared``, ``seam``, ``boundary``,
``partly_shared`` … from the file and the matching together; ``joined_by_geometry`` the
joins that the matching added (whole-side interfaces and stretches), and
``partly_joined_by_geometry`` (where there are any) how many of them are stretches.
"""

from __future__ import annotations

from typing import Any, Collection, Sequence

from .body.topology import find_topology
from .body.trim_edges import find_edge_interfaces, iso_stretches
from .cad_topology import Topology

Edge = tuple[int, str]


def loose_faces(listing: dict[str, Any], kept: Sequence[int],
                trimmed: Collection[int] = ()) -> set[int]:
    """The body's patches (indices into ``kept``) whose file faces are loose (module
    docstring): no edge of the file uses two faces (or one twice) among their uses, and a
    face with edges is not among the file face numbers ``trimmed``."""
    used = {f for edge in listing["edges"] for f in edge["faces"]}
    joined = {f for edge in listing["edges"] if len(edge["faces"]) > 1 for f in edge["faces"]}
    return {k for k, face in enumerate(kept)
            if face not in joined and (face not in used or face not in trimmed)}


def file_edges(listing: dict[str, Any], loose: Collection[int]) -> list[dict[str, Any]]:
    """The file's edges without those of the loose file faces ``loose`` (each used by its
    face alone: a side of its rectangle, joined to nothing)."""
    return [edge for edge in listing["edges"] if not set(edge["faces"]) <= set(loose)]


def join_loose_faces(surfaces: Sequence[Any], topology: Topology, loose: set[int]
                     ) -> Topology:
    """``topology`` (the file's, over ``surfaces``) with the interfaces where a side of a
    ``loose`` surface meets a side no file interface takes, and the stretches where it
    shares part of one (module docstring), its counts updated.

    With ``A`` the interfaces added, ``T`` the stretches (each pair of sides once) and
    ``F`` the sides no interface takes: ``joined_by_geometry = |A| + |T|``,
    ``partly_joined_by_geometry = |T|``; ``non_manifold`` plus the curves where three or
    more sides meet, one of a loose surface (each pair of them an interface of ``A``, as
    :func:`~splinedeform.body.topology.find_topology` gives them), ``shared`` plus the
    other interfaces of ``A`` between two surfaces and ``|T|``, ``partly_shared`` plus
    ``|T|``, ``seam`` plus those of one surface with itself; ``boundary`` plus the loose
    surfaces' sides in ``F`` on no stretch, less the other surfaces' sides (each one file
    edge) in ``A`` or on a stretch. The result's
    :attr:`~splinedeform.cad_topology.Topology.stretches` lists ``T`` as
    ``(a, edge_a, b, edge_b)``.
    """
    if not loose:
        return topology
    found = find_topology(surfaces)
    taken: set[Edge] = {(i.a, i.edge_a) for i in topology.interfaces}
    taken |= {(i.b, i.edge_b) for i in topology.interfaces}
    added = [i for i in found.interfaces
             if (i.a in loose or i.b in loose)
             and (i.a, i.edge_a) not in taken and (i.b, i.edge_b) not in taken]
    taken |= {s for i in added for s in ((i.a, i.edge_a), (i.b, i.edge_b))}
    sides = found.boundary + tuple(s for i in found.interfaces
                                   for s in ((i.a, i.edge_a), (i.b, i.edge_b)))
    free = tuple(dict.fromkeys(s for s in sides if s not in taken))
    parts = {(i.a, i.edge_a, i.b, i.edge_b): None for i in iso_stretches(
        find_edge_interfaces(surfaces, free, set(), found.tol)) if i.a in loose or i.b in loose}
    stretches = list(parts)
    coupled = {s for a, ea, b, eb in stretches for s in ((a, ea), (b, eb))}
    counts = dict(topology.counts)
    groups = [group for group in found.non_manifold if any(p in loose for p, _ in group)]
    grouped = {side for group in groups for side in group}
    manifold = [i for i in added if (i.a, i.edge_a) not in grouped]
    counts["shared"] += sum(i.a != i.b for i in manifold) + len(stretches)
    counts["seam"] += sum(i.a == i.b for i in manifold)
    counts["boundary"] += (sum(p in loose for p, e in free if (p, e) not in coupled)
                           - sum((i.a not in loose) + (i.b not in loose) for i in added)
                           - sum(p not in loose for p, _ in coupled))
    counts["non_manifold"] += len(groups)
    if stretches:                        # keys in the order they are reported
        counts["partly_shared"] = counts.get("partly_shared", 0) + len(stretches)
    counts["joined_by_geometry"] = len(added) + len(stretches)
    if stretches:
        counts["partly_joined_by_geometry"] = len(stretches)
    return Topology(list(topology.interfaces) + added, counts, dict(topology.trim_edges),
                    stretches)
