"""Welded meshes: one vertex where the tessellation grid meets itself, no zero-area triangles.

A ``ru × rv`` parameter grid of a closed or degenerate surface repeats points: the seam
``u = 0 ≡ L`` of a periodic direction, and a pole where a whole grid row maps to one point
(``x_u = 0``, e.g. the half sphere's top). :func:`weld` merges vertices that coincide in
every given frame (distance at most ``tol · diameter``), found with a k-d tree and joined
by connected components, and drops the triangles that then have two equal corners (the
zero-area triangles at a pole). The result is watertight where the surface is closed:
every edge of a torus is shared by exactly two triangles.

Vertex normals are the area-weighted means of the adjacent face normals,
``n_i = Σ_{f ∋ i} (b - a) × (c - a) / |…|``, which is smooth across a welded seam and
well defined at a pole (where ``x_u × x_v = 0``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

#: vertices closer than this fraction of the mesh diameter are one vertex
WELD_TOLERANCE = 1e-9


def weld(frames: ArrayLike, faces: ArrayLike, tol: float = WELD_TOLERANCE
         ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Merge vertices that coincide in every frame; drop triangles that collapse.

    Parameters
    ----------
    frames : array_like, shape ``(N, 3)`` or ``(F, N, 3)``
        Vertex positions, one set per frame on the same grid.
    faces : array_like of int, shape ``(M, 3)``
    tol : float
        Relative weld distance (of the first frame's bounding-box diagonal).

    Returns
    -------
    keep : ndarray of int, shape ``(N',)``
        Index of the vertex kept for each welded vertex (the first of its group): the
        welded positions are ``frames[..., keep, :]``.
    new_faces : ndarray of int, shape ``(M', 3)``
        Faces on the welded vertices, without collapsed triangles.
    """
    X = np.asarray(frames, dtype=float)
    if X.ndim == 2:
        X = X[None]
    F = np.asarray(faces, dtype=np.int64)
    n = X.shape[1]
    first = X[0]
    size = float(np.linalg.norm(first.max(axis=0) - first.min(axis=0))) or 1.0
    radius = tol * size
    pairs = cKDTree(first).query_pairs(radius, output_type="ndarray")
    if pairs.size:
        gap = np.linalg.norm(X[:, pairs[:, 0]] - X[:, pairs[:, 1]], axis=-1).max(axis=0)
        pairs = pairs[gap <= radius]
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])) if len(pairs)
                          else (np.zeros(0), (np.zeros(0, int), np.zeros(0, int))),
                          shape=(n, n))
    _, label = connected_components(graph, directed=False)
    # number the groups in order of their first vertex, so the welded mesh keeps grid order
    keep = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(keep, label, np.arange(n))
    order = np.argsort(keep)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    new_faces = rank[label[F]]
    distinct = (new_faces[:, 0] != new_faces[:, 1]) & (new_faces[:, 1] != new_faces[:, 2]) \
        & (new_faces[:, 0] != new_faces[:, 2])
    return keep[order], new_faces[distinct]


def vertex_normals(vertices: ArrayLike, faces: ArrayLike) -> NDArray[np.float64]:
    """Unit vertex normals: area-weighted means of the adjacent face normals.

    ``n_i ∝ Σ_{f ∋ i} (b_f - a_f) × (c_f - a_f)`` (the cross product has twice the
    area as its length). A vertex whose faces cancel or that has none gets ``(0, 0, 1)``.
    """
    V = np.asarray(vertices, dtype=float)
    Fc = np.asarray(faces, dtype=np.int64)
    a, b, c = V[Fc[:, 0]], V[Fc[:, 1]], V[Fc[:, 2]]
    face_normal = np.cross(b - a, c - a)
    summed = np.zeros_like(V)
    for corner in range(3):
        np.add.at(summed, Fc[:, corner], face_normal)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    fallback = np.broadcast_to([0.0, 0.0, 1.0], V.shape)
    return np.where(length > 1e-300, summed / np.where(length > 1e-300, length, 1.0), fallback)
