"""Exact tangent continuity across smooth lines: ``C^1`` ties in the constraint map.

A line ``Γ`` where two sides meet (a conforming interface or seam, or a ``C^0`` knot line
inside a patch) is **smooth** where the rest shape continues across it in a ``C^1`` way
in the parameters. On each side ``s`` the basis across ``Γ``, taken from inside the side
(:func:`splinedeform.knots.one_sided`), has one function ``i_0`` that is 1 on ``Γ`` and one
more ``i_1`` whose derivative there is not zero (open knots at an edge, a knot of
multiplicity ``p`` inside): the derivative across ``Γ`` is ``β_s (P_{i_0} − P_{i_1})`` row
by row along the line, ``β_s`` constant along it (product weights included). With the
control points along the line ``k``, ``P^0_k`` on it, ``P^a_k`` and ``P^b_k`` the next row
inside ``a`` and ``b``, the rest shape is smooth when one ratio ``r > 0`` holds for all
``k``::

    P^b_k − P^0_k = r (P^0_k − P^a_k)                                   (within TIE_TOLERANCE)

Then the same relation on the displacement,

.. math:: d^b_k − (1 + r)\\, d^0_k + r\\, d^a_k = 0,

makes ``∂_n d`` continuous across ``Γ`` exactly (both sides' derivatives across ``Γ`` are
the rest's ones scaled alike, and the derivative along ``Γ`` is shared), so no rotation
penalty is needed there: the slope jump is round-off and the stiffness keeps its own
conditioning. A crease, a non-conforming interface, general (non-product) weights or a
rest shape whose ratio varies along the line keep the penalty
(:mod:`splinedeform.physics.coupling_model`).

The ties are rows ``C d = 0`` on the concatenated control points; on a map ``d = T q``
they are imposed by :func:`impose`: ``T E`` with ``range E = null(C T)``, each group of
coordinates that shares a row eliminated on its own (a single row: its largest coefficient
solved for; rows that share coordinates, where lines cross: a pivoted QR), so that ``E``
is the identity on every coordinate it keeps and stays sparse. The plate's one unknown per
control point takes ``C`` as it is; the shell's three interleaved displacement components
(dof ``3k + c``) take ``C ⊗ I₃``, the same relation on each component
(:func:`tie_components`): the rest shape and the displacement are then both ``C^1`` across
the line with one ratio, so the shell's rotation ``δa_3`` (which depends on the two tangents
only through their directions and the plane they span) is continuous exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components

from ..body.interface import Interface
from ..boundary import Constraints
from ..knots import one_sided
from ..surface import Surface
from .coupling import c0_lines
from .coupling_traces import Side

Array = NDArray[np.float64]

TIE_TOLERANCE = 1e-9
"""Largest ``|P^b − P^0 − r (P^0 − P^a)|`` along a line, relative to its largest control-point
step: round-off of a smooth rest net (exact for nets drawn at the Greville abscissae, 1e-15
measured), far below a crease or a ratio that varies along the line."""
RANK_TOLERANCE = 1e-10
"""Relative size of the pivots of a pivoted QR below which tie rows are dependent."""


@dataclass(frozen=True)
class Ties:
    """Rows ``C`` (``(rows, N)``) of the smooth lines of a body and which lines they tie.

    Attributes
    ----------
    interfaces : frozenset of int
        Indices (in the topology's interfaces) of the interfaces tied exactly.
    lines : frozenset of (int, str, float)
        ``(patch, direction, knot)`` of the C0 lines tied exactly.
    """

    C: sp.csr_matrix
    interfaces: frozenset[int]
    lines: frozenset[tuple[int, str, float]]


def _rows(side: Side) -> tuple[int, int] | None:
    """Cross indices ``(i_0, i_1)`` of a side (module docstring), or ``None``."""
    across = side.surface.basis_u if side.fixed == "u" else side.surface.basis_v
    index, values = one_sided(across, side.value, -side.outward, 1)
    on = np.flatnonzero(np.abs(values[0]) > 1e-12)
    sloped = np.flatnonzero(np.abs(values[1]) > 1e-12 * np.abs(values[1]).max())
    if on.size != 1 or sloped.size != 2 or on[0] not in sloped:
        return None
    return int(index[on[0]]), int(index[sloped[sloped != on[0]][0]])


def _flat(side: Side, i: int) -> NDArray[np.int64]:
    """Flat indices of the control points of cross index ``i``, in order along the line."""
    n_u, n_v = side.surface.shape
    return i * n_v + np.arange(n_v) if side.fixed == "u" else np.arange(n_u) * n_v + i


def smooth_ratio(rest: Array, line: NDArray[np.int64], inside_a: NDArray[np.int64],
                 inside_b: NDArray[np.int64]) -> float | None:
    """The ratio ``r`` of the module docstring from the rest points ``rest`` ``(N, 3)``, or
    ``None`` where the rest shape is not smooth across the line."""
    ahead, behind = rest[inside_b] - rest[line], rest[line] - rest[inside_a]
    scale = max(float(np.abs(ahead).max()), float(np.abs(behind).max()))
    if scale == 0.0 or not np.any(np.abs(behind) > TIE_TOLERANCE * scale):
        return None
    r = float(np.sum(ahead * behind) / np.sum(behind * behind))
    if r <= 0 or np.abs(ahead - r * behind).max() > TIE_TOLERANCE * scale:
        return None
    return r


def _tie_rows(rest: Array, size: int, line: NDArray[np.int64], inside_a: NDArray[np.int64],
              inside_b: NDArray[np.int64]) -> sp.csr_matrix | None:
    """The rows ``d^b − (1 + r) d^0 + r d^a`` of one line, or ``None`` if it is not smooth."""
    r = smooth_ratio(rest, line, inside_a, inside_b)
    if r is None:
        return None
    k = np.arange(line.size)
    values = np.concatenate([np.ones(k.size), np.full(k.size, -(1.0 + r)), np.full(k.size, r)])
    return sp.csr_matrix((values, (np.tile(k, 3), np.concatenate([inside_b, line, inside_a]))),
                         shape=(k.size, size))


def smooth_ties(patches: Sequence[Surface], interfaces: Sequence[Interface],
                offsets: NDArray[np.int64]) -> Ties:
    """The :class:`Ties` of every smooth conforming interface and C0 line (module docstring).

    ``offsets`` are the patches' first control points in the concatenation (``len + 1``)."""
    rest = np.concatenate([s.control_points.reshape(-1, 3) for s in patches])
    size = int(offsets[-1])
    blocks, tied, lines = [], set(), set()
    for number, interface in enumerate(interfaces):
        a, b = patches[interface.a], patches[interface.b]
        if not interface.conforming or a.net_weights is not None or b.net_weights is not None:
            continue
        side_a, side_b = Side.of_edge(a, interface.edge_a), Side.of_edge(b, interface.edge_b)
        rows_a, rows_b = _rows(side_a), _rows(side_b)
        if rows_a is None or rows_b is None:
            continue
        line = offsets[interface.a] + _flat(side_a, rows_a[0])
        inside_a = offsets[interface.a] + _flat(side_a, rows_a[1])
        inside_b = offsets[interface.b] + _flat(side_b, rows_b[1])
        rows = _tie_rows(rest, size, line, inside_a,
                         inside_b[::-1] if interface.reversed else inside_b)
        if rows is not None:
            blocks.append(rows)
            tied.add(number)
    for p, surface in enumerate(patches):
        if surface.net_weights is not None:
            continue
        for direction, knot in c0_lines(surface):
            below, above = Side(surface, direction, knot, 1), Side(surface, direction, knot, -1)
            rows_a, rows_b = _rows(below), _rows(above)
            if rows_a is None or rows_b is None or rows_a[0] != rows_b[0]:
                continue
            rows = _tie_rows(rest, size, *(offsets[p] + _flat(below, i)
                                           for i in (rows_a[0], rows_a[1], rows_b[1])))
            if rows is not None:
                blocks.append(rows)
                lines.add((p, direction, knot))
    C = sp.vstack(blocks, format="csr") if blocks else sp.csr_matrix((0, size))
    return Ties(C, frozenset(tied), frozenset(lines))


def impose(T: sp.csr_matrix, A: sp.spmatrix) -> tuple[sp.csr_matrix, NDArray[np.int64]]:
    """``T E`` with ``range E = null A`` (``A`` on ``T``'s columns) and the columns kept.

    ``E`` is the identity on the kept columns; each eliminated column is a combination of
    the kept columns of its group (the coordinates connected through rows of ``A``):
    for a group of one row ``a``, the column ``j`` of the largest ``|a_j|`` is
    ``x_j = −Σ_{i≠j} (a_i / a_j) x_i``; for a larger group ``A_g P = Q R`` (pivoted QR) of
    rank ``k``, the first ``k`` pivots are ``x_P1 = −R_11⁻¹ R_12 x_P2``.
    """
    A = sp.csr_matrix(A)
    A.data[np.abs(A.data) <= 1e-14 * max(np.abs(A.data).max(initial=0.0), 1e-300)] = 0.0
    A.eliminate_zeros()
    A = A[np.diff(A.indptr) > 0]
    n = T.shape[1]
    if A.shape[0] == 0:
        return T, np.arange(n)
    pattern = sp.csr_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    groups, label = connected_components(pattern.T @ pattern, directed=False)
    row_group = label[A.indices[A.indptr[:-1]]]
    count = np.bincount(row_group, minlength=groups)
    rows_out, cols_out, vals_out, eliminated = [], [], [], []
    single = count[row_group] == 1
    if np.any(single):                      # one row per group: vectorised
        S = A[np.flatnonzero(single)].tocoo()
        dense_pivot = np.zeros(S.shape[0], dtype=np.int64)
        largest = np.zeros(S.shape[0])
        order = np.lexsort((-np.abs(S.data), S.row))
        first = np.concatenate([[True], np.diff(S.row[order]) != 0])
        dense_pivot[S.row[order][first]] = S.col[order][first]
        largest[S.row[order][first]] = S.data[order][first]
        others = S.col != dense_pivot[S.row]
        rows_out.append(dense_pivot[S.row[others]])
        cols_out.append(S.col[others])
        vals_out.append(-S.data[others] / largest[S.row[others]])
        eliminated.append(dense_pivot)
    for g in np.flatnonzero(count > 1):     # rows sharing coordinates: where lines cross
        block = A[np.flatnonzero(row_group == g)]
        columns = np.unique(block.indices)
        Q, R, P = sla.qr(block[:, columns].toarray(), pivoting=True, mode="economic")
        diag = np.abs(np.diag(R))
        k = int(np.sum(diag > RANK_TOLERANCE * diag[0]))
        pivots, kept = columns[P[:k]], columns[P[k:]]
        X = -sla.solve_triangular(R[:k, :k], R[:k, k:]) if kept.size else np.zeros((k, 0))
        rows_out.append(np.repeat(pivots, kept.size))
        cols_out.append(np.tile(kept, k))
        vals_out.append(X.ravel())
        eliminated.append(pivots)
    gone = np.concatenate(eliminated)
    keep = np.setdiff1d(np.arange(n), gone)
    position = np.full(n, -1)
    position[keep] = np.arange(keep.size)
    rows = np.concatenate([keep] + rows_out)
    cols = np.concatenate([keep] + cols_out)
    vals = np.concatenate([np.ones(keep.size)] + vals_out)
    if np.any(position[cols] < 0):
        raise AssertionError("a tie eliminated a coordinate that another expresses")
    E = sp.csr_matrix((vals, (rows, position[cols])), shape=(n, keep.size))
    return (T @ E).tocsr(), keep


def tie_c0_lines(surface: Surface, constraints: Constraints
                 ) -> tuple[Constraints, set[tuple[str, float]]]:
    """A single surface's constraint map with its smooth C0 lines tied (module docstring)
    and those lines ``(direction, knot)``; unchanged where none is smooth.

    The map keeps its free points (``free_index`` of the coordinates kept) but no longer
    has Kronecker factors (``T_u = T_v = None``)."""
    if not c0_lines(surface):
        return constraints, set()
    ties = smooth_ties([surface], (), np.array([0, surface.shape[0] * surface.shape[1]]))
    if not ties.lines:
        return constraints, set()
    T, kept = impose(constraints.T, ties.C @ constraints.T)
    tied = Constraints(T, None, None, constraints.free_index[kept], constraints.edges,
                       constraints.has_fixed_points)
    return tied, {(direction, knot) for _, direction, knot in ties.lines}


def tie_components(T: sp.csr_matrix, C: sp.spmatrix, components: int = 3) -> sp.csr_matrix:
    """The map ``T`` of interleaved displacements (dof ``components · k + c``) with the ties
    ``C`` (over control points) imposed on every component: ``C ⊗ I`` (module docstring)."""
    if C.shape[0] == 0:
        return T
    rows = sp.kron(C, sp.identity(components), format="csr")
    return impose(T, rows @ T)[0]
