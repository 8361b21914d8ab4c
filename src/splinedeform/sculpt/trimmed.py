"""The samples of trimmed faces: the grid clipped to the trims, as the exports draw it.

A trimmed patch is drawn as its sample grid clipped to the trimmed region ``Ω`` and welded
along the loops (:func:`splinedeform.trim.tessellate.surface_grid`, the mesh of the
exports): the grid points inside ``Ω`` and the points where grid edges cross a loop. The
page keeps every patch's whole ``r_u × r_v`` grid (its layout, normals and indices stay
those of an untrimmed face) and appends the crossing points after the grids of all
patches,

    samples = [grid of patch 0, …, grid of patch P-1, crossings of every trimmed patch],

each crossing tagged with its patch. The triangles drawn are those of the clipped mesh
(untrimmed patches: their whole grid) in these indices; a grid point outside ``Ω`` is in
no triangle and cannot be grabbed (:attr:`TrimmedSamples.inside` is False there). Its
modal row is the WEB-spline extension's continuation of the modes, so nothing drawn
depends on it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..surface import grid_faces

Array = NDArray[np.float64]


@dataclass(frozen=True)
class TrimmedSamples:
    """What trimming adds to the sample grids of a model's patches.

    Attributes
    ----------
    patch : (C,) the patch of each crossing point.
    uv : (C, 2) the crossing points' parameters, on a trim loop.
    triangles : (F, 3) the triangles drawn, in sample indices (grids, then crossings),
        oriented like ``x_u × x_v``.
    inside : (S,) whether each sample lies in its patch's trimmed region (crossing
        points: on its boundary, inside).
    """

    patch: NDArray[np.int64]
    uv: Array
    triangles: NDArray[np.int64]
    inside: NDArray[np.bool_]


def trimmed_samples(patches: tuple[Any, ...],
                    samples: tuple[tuple[Array, Array], ...]) -> TrimmedSamples | None:
    """The crossing points, triangles and inside mask of ``patches`` sampled on their grids
    ``samples`` (all of one shape ``r_u × r_v``); None when no patch is trimmed.

    The clipped mesh of :func:`~splinedeform.trim.tessellate.surface_grid` lists the grid
    points inside ``Ω`` first (row-major: the inside vertices of every kept or cut
    triangle, which are all of them), then the crossings; its indices are mapped onto the
    page's samples by that order.
    """
    from ..trim.surface_trim import region_contains
    from ..trim.tessellate import surface_grid

    if all(getattr(s, "trim", None) is None for s in patches):
        return None
    ru, rv = samples[0][0].size, samples[0][1].size
    count = ru * rv
    grid_total = len(patches) * count
    patch_of, crossings, triangles, inside = [], [], [], []
    extra = grid_total
    for p, (surface, (u, v)) in enumerate(zip(patches, samples)):
        base = p * count
        if surface.trim is None:
            triangles.append(grid_faces(ru, rv) + base)
            inside.append(np.ones(count, bool))
            continue
        grid = np.stack(np.meshgrid(u, v, indexing="ij"), axis=-1).reshape(-1, 2)
        within = np.asarray(region_contains(surface, grid), bool)
        uv, faces = surface_grid(surface, u, v)
        kept = np.flatnonzero(within)
        spacing = min(np.diff(u).min(), np.diff(v).min())
        # the mesh's first points are the grid points inside, in order (half a grid
        # spacing tells two grid points apart; round-off is 1e-16 of it)
        if len(uv) < kept.size or np.abs(uv[:kept.size] - grid[kept]).max(initial=0.0) > 0.5 * spacing:
            raise RuntimeError("the clipped mesh does not list the grid points inside first")
        where = np.concatenate([base + kept, extra + np.arange(len(uv) - kept.size)])
        triangles.append(where[faces])
        crossings.append(uv[kept.size:])
        patch_of.append(np.full(len(uv) - kept.size, p))
        inside.append(within)
        extra += len(uv) - kept.size
    cross = np.concatenate(crossings) if crossings else np.zeros((0, 2))
    return TrimmedSamples(
        patch=np.concatenate(patch_of).astype(np.int64) if patch_of else np.zeros(0, np.int64),
        uv=cross, triangles=np.concatenate(triangles).astype(np.int64),
        inside=np.concatenate(inside + [np.ones(len(cross), bool)]))


def outside_words(surface: Any, u: float, v: float) -> str:
    """Why a grab at ``(u, v)`` outside the trims of ``surface`` is refused."""
    return (f"the point u = {u:.4g}, v = {v:.4g} lies outside the trims of the surface (a "
            "cut-away part is not in the model); grab the surface inside its trim loops")
