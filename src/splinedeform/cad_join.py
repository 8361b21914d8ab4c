"""Loose surfaces of a CAD file joined to its Breps where their edges meet.

A ``.3dm`` file may hold Breps beside plain NURBS surfaces that touch them. A Brep's edges
come from the file (:func:`splinedeform.cad_topology.body_topology`); a plain surface has
none, so where its sides meet a Brep face's side, another plain surface or itself (a seam)
is found from the geometry, as for a file of plain surfaces only
(:func:`splinedeform.body.topology.find_topology`: the sides sampled and matched within
``1e-6`` of the body's bounding-box diagonal). Only the sides that the file leaves unjoined
take part: a Brep's boundary edge (one face uses it) can meet a loose surface, two Brep
faces that the file does not join are not joined here. The counts then say which edges
came from which: ``shared``, ``seam``, ``boundary`` … from the file and the matching
together, ``joined_by_geometry`` the interfaces that the matching added.
"""

from __future__ import annotations

from typing import Any, Sequence

from .body.topology import find_topology
from .cad_topology import Topology

Edge = tuple[int, str]


def loose_faces(listing: dict[str, Any], kept: Sequence[int]) -> set[int]:
    """The body's patches (indices into ``kept``) whose file faces no file edge uses: the
    plain surfaces of a ``.3dm`` (a Brep face always has its loops' edges)."""
    used = {f for edge in listing["edges"] for f in edge["faces"]}
    return {k for k, face in enumerate(kept) if face not in used}


def join_loose_faces(surfaces: Sequence[Any], topology: Topology, loose: set[int]
                     ) -> Topology:
    """``topology`` (the file's, over ``surfaces``) with the interfaces where a side of a
    ``loose`` surface meets a side no file interface takes (module docstring), and its
    counts updated: ``joined_by_geometry`` the interfaces added; ``shared`` and ``seam``
    those among them between two surfaces and of one surface with itself; ``boundary``
    less the Brep sides now joined, plus the loose surfaces' sides that meet nothing;
    ``non_manifold`` plus the curves where three or more sides of loose surfaces meet."""
    if not loose:
        return topology
    found = find_topology(surfaces)
    taken: set[Edge] = {(i.a, i.edge_a) for i in topology.interfaces}
    taken |= {(i.b, i.edge_b) for i in topology.interfaces}
    added = [i for i in found.interfaces
             if (i.a in loose or i.b in loose)
             and (i.a, i.edge_a) not in taken and (i.b, i.edge_b) not in taken]
    counts = dict(topology.counts)
    brep_sides = sum((i.a not in loose) + (i.b not in loose) for i in added)
    counts["shared"] += sum(i.a != i.b for i in added)
    counts["seam"] += sum(i.a == i.b for i in added)
    counts["boundary"] += (sum(p in loose for p, _ in found.boundary) - brep_sides)
    counts["non_manifold"] += sum(any(p in loose for p, _ in group)
                                  for group in found.non_manifold)
    counts["joined_by_geometry"] = len(added)
    return Topology(list(topology.interfaces) + added, counts)
