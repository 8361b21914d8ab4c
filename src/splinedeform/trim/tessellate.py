"""A parameter grid's triangles clipped to a trimmed region and welded along the loops.

The ``r_u × r_v`` grid of :meth:`~splinedeform.Surface.sample_parameters` is split in two
triangles per quad (:func:`~splinedeform.surface.grid_faces`). Triangles with all three
vertices inside ``Ω`` are kept, those with none dropped; a cut triangle keeps its part
inside: one vertex inside gives the triangle ``(a, p_ab, p_ca)``, two inside the quad
``(p_ab, b, c, p_ca)`` as two triangles, orientation kept. Each crossing point ``p_ab``
lies on the trim loop (bisection of the grid edge ``ab`` with the exact point-in-region
test, to round-off) and is one vertex for both triangles sharing the edge, so the mesh
is welded along the loops. What is lost is the chord error: between two crossing points
the mesh follows the chord, not the loop (for a circle of radius ``r`` and chord ``s``,
an area of about ``s³ / (12 r)`` per chord).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray

from ..surface import grid_faces
from .loops import TrimDomain
from .surface_trim import region_contains

BISECTIONS = 60
"""Halvings of a crossing grid edge: ``2⁻⁶⁰`` of its length, below round-off."""


Contains = Callable[[NDArray[np.float64]], NDArray[np.bool_]]


def crossing_points(contains: Contains, inside: NDArray[np.float64],
                    outside: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points on ``∂Ω`` between ``inside`` and ``outside`` points ``(E, 2)`` by bisection
    with the point-in-region test ``contains``."""
    a, b = inside.copy(), outside.copy()
    for _ in range(BISECTIONS):            # halvings of all edges at once
        mid = 0.5 * (a + b)
        keep = contains(mid)[:, None]
        a, b = np.where(keep, mid, a), np.where(keep, b, mid)
    return 0.5 * (a + b)


def surface_grid(surface: Any, u: NDArray[np.float64], v: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """:func:`clipped_grid` of a trimmed surface's region (the rectangle's own edges inside
    when it is the outer loop, :func:`~splinedeform.trim.surface_trim.region_contains`)."""
    return clipped_grid(surface.trim, u, v, lambda p: region_contains(surface, p))


def clipped_grid(domain: TrimDomain, u: NDArray[np.float64], v: NDArray[np.float64],
                 contains: Contains | None = None
                 ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Parameters ``(N, 2)`` and faces ``(F, 3)`` of the grid ``u × v`` clipped to ``Ω``
    (``contains`` its point test, default ``domain.contains``)."""
    contains = domain.contains if contains is None else contains
    points = np.stack(np.meshgrid(u, v, indexing="ij"), axis=-1).reshape(-1, 2)
    faces = grid_faces(u.size, v.size)
    inside = contains(points)
    count = inside[faces].sum(axis=1)
    whole = faces[count == 3]
    cut = faces[(count == 1) | (count == 2)]
    lone = count[(count == 1) | (count == 2)]
    # rotate each cut face so that its odd vertex (the one inside of one, the one
    # outside of two) comes first; the cyclic order, hence the orientation, is kept
    odd = inside[cut] == (lone == 1)[:, None]
    first = np.argmax(odd, axis=1)
    turn = (first[:, None] + np.arange(3)) % 3
    a, b, c = np.take_along_axis(cut, turn, axis=1).T
    n = len(points)
    edges = np.concatenate([np.sort(np.stack([a, b], 1), axis=1),
                            np.sort(np.stack([c, a], 1), axis=1)])
    keys, slot = np.unique(edges[:, 0] * n + edges[:, 1], return_inverse=True)
    ends = np.stack([keys // n, keys % n], axis=1)
    end_in = inside[ends[:, 0]]
    start = np.where(end_in, ends[:, 0], ends[:, 1])
    stop = np.where(end_in, ends[:, 1], ends[:, 0])
    crossings = crossing_points(contains, points[start], points[stop])
    p_ab, p_ca = n + slot[:len(a)], n + slot[len(a):]
    one, two = lone == 1, lone == 2
    new = np.concatenate([
        np.stack([a, p_ab, p_ca], 1)[one],
        np.stack([p_ab, b, c], 1)[two],
        np.stack([p_ab, c, p_ca], 1)[two]])
    all_points = np.concatenate([points, crossings])
    all_faces = np.concatenate([whole, new]).astype(np.int64)
    used = np.zeros(len(all_points), bool)
    used[all_faces.ravel()] = True
    index = np.cumsum(used) - 1
    return all_points[used], index[all_faces]
