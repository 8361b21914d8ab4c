"""The constraint map of a body: merged control points and per-patch edge conditions.

The unknowns of a body are all its patches' control points, patch after patch (row-major in
each), ``N = Σ n_u n_v``. The map ``d = T d_free`` is built in two steps:

1. **Edge conditions per patch.** Each patch gets ``free`` on its interface and pole edges
   and the body's preset (``free``, ``pinned``, ``clamped``) on its boundary edges:
   ``T_p`` of :func:`splinedeform.boundary.build_constraints`, and ``T_b = diag(T_p)``.
2. **Merging.** Points that must move as one are joined into classes: along a conforming
   interface the ``k``-th control point of edge ``a`` with the ``k``-th (``reversed``: the
   ``k``-th from the end) of edge ``b``; on a pole all control points of the degenerate edge.
   A non-conforming interface merges nothing: its penalty couples it
   (:mod:`splinedeform.physics.coupling_model`).
   The classes are the connected components of that graph (union-find, by
   :func:`scipy.sparse.csgraph.connected_components`), so a corner shared by three or more
   patches, a seam and a pole come out as one class each. With ``S`` mapping the columns
   of ``T_b`` to classes, ``T = T_b S``: the columns of one class are summed, and a class
   with a member that its patch's edge condition fixes (a zero row of ``T_b``) is fixed as a
   whole. Displacement continuity across the interface is then exact.
   **Fixed points.** A mask of fixed control points per patch (:func:`body_fixed_mask`)
   fixes the classes of the points it marks as the edge presets do: a class with a masked
   member is dropped from ``S``, so its rows of ``T`` are zero. A point shared by several
   patches (one class) is therefore fixed when any one of them fixes it. As for a single
   surface (:func:`splinedeform.boundary.build_constraints`), a point that its edge
   condition determines from others (not a coefficient of its own) follows that condition.
   A trimmed face's mask is left to its own map (:func:`trimmed_face_masks`,
   :func:`~splinedeform.body.trimmed.with_trimmed_faces`): its points are merged with no
   other face's, so they are held in that face alone.
3. **Ties.** Where the energy bends, the tangent continuity across smooth conforming
   interfaces and C0 lines is imposed exactly too: ``T = T_b S E`` with
   ``range E = null(C T_b S)`` for the ties ``C d = 0`` of
   :mod:`splinedeform.physics.coupling_ties`.

A merged point must be a coefficient of its own (a unit row of ``T_b``) or fixed (a zero
row): knot layouts whose edge conditions couple several coefficients (Höllig's uniform
knots) cannot be merged and are refused.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.sparse.csgraph import connected_components

from ..boundary import EDGES, build_constraints, edge_points
from ..errors import InputError
from ..surface import Surface
from ..physics.coupling_ties import Ties, impose, smooth_ties
from .topology import Edge, Topology

BODY_PRESETS = ("free", "pinned", "clamped")
NO_TIES = Ties(sp.csr_matrix((0, 0)), frozenset(), frozenset())


@dataclass(frozen=True)
class BodyConstraints:
    """The map ``d = T d_free`` of a body (module docstring).

    Attributes
    ----------
    T : scipy.sparse.csr_matrix, shape ``(N, n_free)``
    free_index : ndarray of int
        Row (body-wide point index) of the first point of each free coordinate's class.
    edges : dict
        The preset of each boundary edge, keyed ``(patch, edge)``.
    offsets : ndarray of int
        First row of each patch (``len(patches) + 1`` values).
    ties : Ties
        The interfaces and C0 lines whose tangent continuity ``T`` holds exactly
        (:mod:`splinedeform.physics.coupling_ties`), which need no rotation penalty.
    fixed_patches : frozenset of int
        The patches with a control point that the mask of fixed points holds (its own
        mask or a neighbour's across a merged point).
    """

    T: sp.csr_matrix
    free_index: NDArray[np.int64]
    edges: dict[Edge, str]
    offsets: NDArray[np.int64]
    ties: Ties = field(default_factory=lambda: NO_TIES)
    fixed_patches: frozenset[int] = frozenset()
    T_u: None = field(default=None, init=False)
    T_v: None = field(default=None, init=False)

    @property
    def has_fixed_points(self) -> bool:
        """Whether a mask of fixed control points (:func:`body_fixed_mask`) holds a point."""
        return bool(self.fixed_patches)

    @property
    def n_free(self) -> int:
        return int(self.T.shape[1])

    @property
    def unconstrained(self) -> bool:
        """No boundary edge is pinned or clamped and no control point is fixed: rigid
        motions are free."""
        return (all(preset == "free" for preset in self.edges.values())
                and not self.has_fixed_points)


def boundary_presets(boundary: str | Mapping[Edge, str], topology: Topology,
                     kinds: Sequence[str] = BODY_PRESETS) -> dict[Edge, str]:
    """``"clamped"`` for every boundary edge, or ``{(patch, edge): preset}`` (missing: free).

    ``kinds`` are the names a preset may take (the shell's edge kinds for a shell body)."""
    edges = list(topology.boundary)
    if isinstance(boundary, str):
        if boundary not in kinds:
            raise InputError(f"boundary preset must be one of {tuple(kinds)}, got {boundary!r}")
        return {edge: boundary for edge in edges}
    if not isinstance(boundary, Mapping):
        raise InputError(f"a body's boundary is a preset name or a mapping (patch, edge) -> "
                         f"preset, got {type(boundary).__name__}")
    out = {edge: "free" for edge in edges}
    joined = {(i.a, i.edge_a): (i.b, i.edge_b) for i in topology.interfaces}
    joined.update({(i.b, i.edge_b): (i.a, i.edge_a) for i in topology.interfaces})
    for key, preset in boundary.items():
        if preset not in kinds:
            raise InputError(f"boundary[{key!r}] must be one of {tuple(kinds)}, got {preset!r}")
        if key in joined:
            other = joined[key]
            raise InputError(f"boundary[{key!r}]: edge {key[1]} of patch {key[0]} is an "
                             f"interface with edge {other[1]} of patch {other[0]}, not a "
                             "boundary edge")
        if key in topology.poles:
            raise InputError(f"boundary[{key!r}]: edge {key[1]} of patch {key[0]} is a pole "
                             "(collapsed to a point), not a boundary edge")
        if key not in out:
            raise InputError(f"boundary[{key!r}] names no boundary edge; the boundary edges "
                             f"are {edges}")
        out[key] = preset
    return out


def edge_rows(surface: Surface, edge: str) -> NDArray[np.int64]:
    """Flat (row-major) indices of the control points on ``edge``, in order along it."""
    index = np.arange(surface.shape[0] * surface.shape[1]).reshape(surface.shape + (1,))
    return edge_points(index, edge)[:, 0]


def body_fixed_mask(patches: Sequence[Surface], fixed: Sequence[ArrayLike | None] | None,
                    components: bool = False) -> NDArray[np.bool_] | None:
    """The body-wide mask of fixed control points of the untrimmed patches: their masks,
    row-major each, patch after patch (``N = Σ n_u n_v`` values, False on every trimmed
    face, whose mask its own map takes: :func:`trimmed_face_masks`), or ``None`` where
    none fixes a point.

    Parameters
    ----------
    fixed : sequence of bool arrays ``(n_u, n_v)`` or None, optional
        One entry per patch, ``True`` = held at rest; ``None`` for a patch with nothing
        fixed beyond its edge conditions.
    components : bool
        Also take a mask ``(n_u, n_v, 3)`` per displacement component (the shell's three
        unknowns per point); the result is then per component, interleaved (``3N``
        values, entry ``3k + c`` component ``c`` of point ``k``), a mask ``(n_u, n_v)``
        holding all three components of its points.

    Raises
    ------
    InputError
        A count other than one per patch, or a mask of another shape than its patch's net
        or not boolean, naming the patch.
    """
    checked = _checked_masks(patches, fixed, components)
    if checked is None:
        return None
    per = 3 if components else 1
    masks = []
    for surface, mask in zip(patches, checked):
        net = tuple(surface.shape)
        if mask is None or surface.trim is not None:
            masks.append(np.zeros(net[0] * net[1] * per, dtype=bool))
            continue
        if components and mask.shape == net:         # a whole point: its three components
            mask = np.repeat(mask[..., None], 3, axis=-1)
        masks.append(mask.ravel())
    out = np.concatenate(masks)
    return out if out.any() else None


def trimmed_face_masks(patches: Sequence[Surface], fixed: Sequence[ArrayLike | None] | None,
                       components: bool = False) -> dict[int, NDArray[np.bool_]]:
    """The masks ``(n_u, n_v)`` of fixed control points of the trimmed faces, ``{face:
    mask}`` for those with a point fixed, checked as :func:`body_fixed_mask` checks them.
    A trimmed face's map is Höllig's extension of its own points
    (:func:`~splinedeform.trim.holed.with_edges` takes the mask), the same for the three
    components of the shell: a mask ``(n_u, n_v, 3)`` (``components``) must hold the three
    components of a point alike.

    Raises
    ------
    InputError
        As :func:`body_fixed_mask`, and a per-component mask on a trimmed face that holds
        some components of a point but not all, naming the face and the points.
    """
    from ..trim.shell_trimmed import point_mask

    checked = _checked_masks(patches, fixed, components)
    out: dict[int, NDArray[np.bool_]] = {}
    for p, (surface, mask) in enumerate(zip(patches, checked or ())):
        if mask is None or surface.trim is None or not mask.any():
            continue
        try:
            out[p] = point_mask(surface, mask)
        except InputError as exc:
            raise InputError(f"fixed[{p}]: face {p} is trimmed: {exc}") from None
    return out


def _checked_masks(patches: Sequence[Surface], fixed: Sequence[ArrayLike | None] | None,
                   components: bool) -> list[NDArray[np.bool_] | None] | None:
    """``fixed`` as one boolean array (or None) per patch, its count, shapes and types
    checked (:func:`body_fixed_mask`)."""
    if fixed is None:
        return None
    if isinstance(fixed, np.ndarray) or not isinstance(fixed, Sequence):
        raise InputError(f"fixed must be a sequence of one mask (or None) per patch, got "
                         f"{type(fixed).__name__}")
    if len(fixed) != len(patches):
        raise InputError(f"fixed has {len(fixed)} masks for a body of {len(patches)} "
                         "patches: give one per patch (None where nothing is fixed)")
    out: list[NDArray[np.bool_] | None] = []
    for p, (surface, mask) in enumerate(zip(patches, fixed)):
        if mask is None:
            out.append(None)
            continue
        net = tuple(surface.shape)
        mask = np.asarray(mask)
        if mask.shape != net and not (components and mask.shape == net + (3,)):
            also = f" or, per component, {net + (3,)}" if components else ""
            raise InputError(f"fixed[{p}]: the mask of patch {p} must have the shape of its "
                             f"control net (n_u, n_v) = {net}{also}, got {mask.shape}")
        if mask.dtype != bool:
            raise InputError(f"fixed[{p}]: the mask of patch {p} must be boolean, got dtype "
                             f"{mask.dtype}")
        out.append(mask)
    return out


def merged_classes(patches: Sequence[Surface], topology: Topology) -> NDArray[np.int64]:
    """The class of each control point of the body (rows patch after patch, row-major in
    each): points that move as one (a conforming interface's ``k``-th points, a pole's
    points) share a class, the connected components of those pairs (module docstring,
    step 2); a point on no interface or pole is a class of its own."""
    sizes = np.array([s.shape[0] * s.shape[1] for s in patches])
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    pairs = [np.zeros((0, 2), dtype=np.int64)]
    for i in (i for i in topology.interfaces if i.conforming):
        ra = offsets[i.a] + edge_rows(patches[i.a], i.edge_a)
        rb = offsets[i.b] + edge_rows(patches[i.b], i.edge_b)
        pairs.append(np.stack([ra, rb[::-1] if i.reversed else rb], axis=1))
    for p, e in topology.poles:
        rows = offsets[p] + edge_rows(patches[p], e)
        pairs.append(np.stack([np.full(rows.size, rows[0]), rows], axis=1))
    pair = np.concatenate(pairs)
    n = int(offsets[-1])
    graph = sp.coo_matrix((np.ones(len(pair)), (pair[:, 0], pair[:, 1])), shape=(n, n))
    return connected_components(graph, directed=False)[1].astype(np.int64)


def build_body_constraints(patches: Sequence[Surface], topology: Topology,
                           presets: dict[Edge, str], smooth: bool = False,
                           fixed: NDArray[np.bool_] | None = None) -> BodyConstraints:
    """``T = T_b S`` (module docstring): conforming interfaces merged, the given presets;
    with ``smooth`` (an energy that bends) also ``T = T_b S E``, the smooth lines tied.
    ``fixed`` (:func:`body_fixed_mask`, ``N`` values) fixes the classes of the points it
    marks: their rows of ``T`` are zero.

    Returns
    -------
    BodyConstraints
        Its ``ties`` name the interfaces and C0 lines tied exactly
        (:mod:`splinedeform.physics.coupling_ties`)."""
    sizes = np.array([s.shape[0] * s.shape[1] for s in patches])
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    mask = None if fixed is None else np.asarray(fixed, dtype=bool)
    maps, columns = [], []
    for p, surface in enumerate(patches):
        own = {e: presets.get((p, e), "free") for e in EDGES}
        c = build_constraints(surface.basis_u, surface.basis_v, own)
        maps.append(c.T)
        columns.append(offsets[p] + c.free_index)
    Tb = sp.block_diag(maps, format="csr")
    column_point = np.concatenate(columns)
    n = int(offsets[-1])
    label = merged_classes(patches, topology)
    merged = np.bincount(label, minlength=n)[label] > 1
    is_column = np.zeros(n, dtype=bool)
    is_column[column_point] = True
    fixed = (Tb.getnnz(axis=1) == 0) & ~is_column
    coupled = merged & ~is_column & ~fixed
    if np.any(coupled):
        row = int(np.flatnonzero(coupled)[0])
        p = int(np.searchsorted(offsets, row, side="right") - 1)
        raise InputError(f"control point {divmod(row - offsets[p], patches[p].shape[1])} of "
                         f"patch {p} lies on an interface or pole but its edge condition "
                         "couples it to other control points (uniform knots): use open knots "
                         "at edges that meet")
    held = np.zeros(n, dtype=bool) if mask is None else mask & is_column
    held_class = np.bincount(label, weights=held, minlength=label.max() + 1) > 0
    class_fixed = (np.bincount(label, weights=fixed, minlength=label.max() + 1) > 0) | held_class
    column_class = label[column_point]
    keep = ~class_fixed[column_class]
    classes, new = np.unique(column_class[keep], return_inverse=True)
    S = sp.csr_matrix((np.ones(new.size), (np.flatnonzero(keep), new)),
                      shape=(column_point.size, classes.size))
    first = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(first, label, np.arange(n))
    T, free_index = (Tb @ S).tocsr(), first[classes]
    if T.shape[1] == 0 and held.any():
        raise InputError("every control point is fixed: nothing can move")
    ties = smooth_ties(patches, topology.interfaces, offsets) if smooth else NO_TIES
    if ties.C.shape[0]:
        T, kept = impose(T, ties.C @ T)
        free_index = free_index[kept]
    held_patches = frozenset(int(p) for p in np.searchsorted(
        offsets, np.flatnonzero(held_class[label]), side="right") - 1)
    return BodyConstraints(T, free_index, dict(presets), offsets, ties, held_patches)
