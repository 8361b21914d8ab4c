"""Boundary conditions as a sparse constraint map ``d = T d_free`` (DESIGN.md §1.6).

Per edge a preset: ``free``, ``pinned`` (``d = 0`` on the edge), ``clamped`` (``d = 0``
and ``∂_n d = 0``) or ``pole`` (a degenerate edge, such as the pole of a sphere, whose
control points coincide: they move as one point, so the surface does not tear there; an
edge whose control points do not coincide is refused, see :func:`check_poles`). In one direction the end conditions are linear constraints
``C c = 0`` on the coefficients ``c`` of the 1-D basis, ``C`` made of rows ``b(x_e)`` and
``b'(x_e)`` at the ends. For open knots these are ``c_0 = 0`` (and ``c_1 = 0``); for
Höllig's uniform knots they couple the ``n`` outer coefficients. Each end's constraints are
solved for as many of its outermost coefficients (pivoted), giving a sparse ``T_1d``
whose columns are the kept coefficients. Per-edge conditions give ``T = T_u ⊗ T_v``.
A mask of fixed control points removes further columns (the paper's reduced set of moving
control points); when the free region is a rectangle of the net the Kronecker form survives.

The 1-D maps of a basis and two end presets are kept in the bounded ``constraint_map``
cache of :mod:`splinedeform.construction_cache` (read-only there, each caller gets a copy;
:func:`~splinedeform.construction_cache.clear_caches` empties it); ``T_u ⊗ T_v`` is built
directly in CSR form (:func:`splinedeform.kronecker.kron`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray

from .basis import BSplineBasis
from .construction_cache import BoundedCache, basis_key, read_only
from .errors import InputError
from .kronecker import kron

PRESETS = ("free", "pinned", "clamped", "pole")
EDGES = ("u0", "u1", "v0", "v1")
POLE_TOLERANCE = 1e-8
"""A pole edge's control points lie within this fraction of the net's size (the diagonal of
its bounding box) of its first one: round-off of a file, not a shape."""


def edge_points(control_points: NDArray[np.float64], edge: str) -> NDArray[np.float64]:
    """The control points on ``edge`` of a net ``(n_u, n_v, 3)``, in order along it."""
    return {"u0": control_points[0], "u1": control_points[-1],
            "v0": control_points[:, 0], "v1": control_points[:, -1]}[edge]


def check_poles(edges: Mapping[str, str], control_points: NDArray[np.float64]) -> None:
    """Refuse a ``pole`` edge that is not collapsed.

    A pole edge moves as one point, so its control points must coincide:
    ``max_k |P_k - P_0| <= POLE_TOLERANCE · |max P - min P|`` over the edge's points
    ``P_k``, the right side being the diagonal of the net's bounding box. Otherwise the
    whole edge would move rigidly as one point; the error names the edge and the length of
    its control polygon ``Σ_k |P_{k+1} - P_k|``.
    """
    P = np.asarray(control_points, dtype=float)
    size = float(np.linalg.norm(P.max(axis=(0, 1)) - P.min(axis=(0, 1))))
    for edge in (e for e in EDGES if edges.get(e) == "pole"):
        row = edge_points(P, edge)
        spread = float(np.max(np.linalg.norm(row - row[0], axis=-1)))
        if spread > POLE_TOLERANCE * size:
            length = float(np.sum(np.linalg.norm(np.diff(row, axis=0), axis=-1)))
            error = InputError(
                f"boundary.{edge} = 'pole' needs a collapsed edge (all its control points at "
                f"one point), but the control polygon of edge {edge} is {length:.6g} long "
                f"({length / size:.3g} of the net's size {size:.6g}): the whole edge would "
                "move as one point; use 'free', 'pinned' or 'clamped' there")
            error.key = f"boundary.{edge}"  # type: ignore[attr-defined]
            raise error


def edge_conditions(boundary: str | Mapping[str, str]) -> dict[str, str]:
    """Normalise ``"clamped"`` or ``{"u0": ..., ...}`` to a preset for each of the four edges."""
    if isinstance(boundary, str):
        if boundary not in PRESETS:
            raise InputError(f"boundary preset must be one of {PRESETS}, got {boundary!r}")
        return {e: boundary for e in EDGES}
    if not isinstance(boundary, Mapping):
        raise InputError(f"boundary must be a preset name or a mapping edge -> preset, got "
                         f"{type(boundary).__name__}")
    unknown = set(boundary) - set(EDGES)
    if unknown:
        raise InputError(f"unknown boundary edge(s) {sorted(unknown)}; edges are {EDGES}")
    out = {e: boundary.get(e, "free") for e in EDGES}
    for e, preset in out.items():
        if preset not in PRESETS:
            raise InputError(f"boundary.{e} must be one of {PRESETS}, got {preset!r}")
    return out


LOOP_PRESETS = ("free", "pinned", "clamped")


def trim_conditions(boundary: str | Mapping[str, str], loops: tuple[str, ...],
                    rectangle: bool = False, trim_edges: Mapping[str, int] | None = None
                    ) -> tuple[dict[str, str], dict[str, str]]:
    """Presets of the rectangle's edges and of the trim loops of a trimmed surface.

    A preset name holds every trim loop; a mapping names edges (``u0`` …), loops
    (``outer``, ``hole1`` …) and, of a loop made of ``trim_edges[name] > 1`` trim edges, one
    edge (``outer.0`` …, numbered from 0 in the loop's order), missing ones free (an edge
    not named takes its loop's preset). The rectangle's edges bound the region only when
    the outer loop is the rectangle itself (``rectangle``): then they take the presets (a
    preset name holds them too) and the loop ``outer`` is theirs; otherwise they lie
    outside the region and any preset but ``free`` there is refused. The loops' presets
    come back under their names and the named trim edges under ``name.k``.
    """
    counts = {name: (trim_edges or {}).get(name, 1) for name in loops}
    if isinstance(boundary, str):
        if boundary not in LOOP_PRESETS:
            raise InputError(f"a trim loop's preset must be one of {LOOP_PRESETS}, got "
                             f"{boundary!r}")
        presets = {name: boundary for name in loops}
        if rectangle:
            presets["outer"] = "free"
        return {e: boundary if rectangle else "free" for e in EDGES}, presets
    if not isinstance(boundary, Mapping):
        raise InputError(f"boundary must be a preset name or a mapping edge/loop -> preset, "
                         f"got {type(boundary).__name__}")
    split = {f"{name}.{k}" for name, count in counts.items() if count > 1 for k in range(count)}
    unknown = set(boundary) - set(EDGES) - set(loops) - split
    if unknown:
        edges_of = "".join(f", {name}.0 … {name}.{c - 1}" for name, c in counts.items() if c > 1)
        raise InputError(f"unknown boundary edge(s) or loop(s) {sorted(unknown)} of a trimmed "
                         f"surface; its loops are {loops}{edges_of and ' (trim edges'}"
                         f"{edges_of[1:]}{edges_of and ')'}, its edges {EDGES}")
    edges = {e: boundary.get(e, "free") for e in EDGES}
    presets = {name: boundary.get(name, "free") for name in loops}
    presets.update({key: boundary[key] for key in sorted(split & set(boundary))})
    for name, preset in {**edges, **presets}.items():
        if preset not in LOOP_PRESETS:
            raise InputError(f"boundary.{name} must be one of {LOOP_PRESETS}, got {preset!r}")
    held = [e for e, preset in edges.items() if preset != "free"]
    if held and not rectangle:
        raise InputError(f"boundary.{held[0]} = {edges[held[0]]!r}: the trimmed region is "
                         f"bounded by its trim loops {loops}, not by the rectangle's edges "
                         "(make the outer loop the rectangle itself to hold them)")
    outer = [k for k in presets if k.split(".")[0] == "outer" and presets[k] != "free"]
    if rectangle and outer:
        raise InputError(f"boundary.{outer[0]} = {presets[outer[0]]!r}: the outer loop is the "
                         f"rectangle itself; hold its edges {EDGES} instead")
    return edges, presets


def _end_rows(basis: BSplineBasis, end: int, preset: str) -> NDArray[np.float64]:
    """Rows ``D^j b(x_e)``, ``j < r``, with ``r = 0, 1, 2`` for free (or pole), pinned,
    clamped, as a dense ``(r, size)`` array (one evaluation of the basis and its
    derivatives at the end)."""
    order = {"free": 0, "pole": 0, "pinned": 1, "clamped": 2}[preset]
    C = np.zeros((order, basis.size))
    if order:
        index, values = basis.nonzero_derivatives(
            np.array([0.0 if end == 0 else basis.length]), order - 1)
        for j in range(order):
            np.add.at(C[j], index[0], values[j, 0])
    return C


_MAPS = BoundedCache("constraint_map", 256, 64 * 2**20,
                     lambda m: m[0].data.nbytes + m[0].indices.nbytes + m[0].indptr.nbytes
                     + m[1].nbytes)


def constraint_map(basis: BSplineBasis, start: str, end: str
                   ) -> tuple[sp.csr_matrix, NDArray[np.int64]]:
    """1-D constraint map ``T`` (size × kept) and the indices of the kept coefficients.

    The constrained coefficients of each end are eliminated: with the end's rows split into
    the eliminated columns ``E`` and the rest ``R``, ``c_E = -C_E^{-1} C_R c_R``. Copies of
    the cached map of ``(basis, start, end)`` (module docstring).
    """
    if basis.periodic and (start, end) != ("free", "free"):
        raise InputError(f"a periodic direction has no edges; its boundary presets must be "
                         f"'free', got {start!r} and {end!r}")
    T, kept = _MAPS.get((basis_key(basis), start, end),
                        lambda: _constraint_map(basis, start, end))
    return T.copy(), kept.copy()


def _constraint_map(basis: BSplineBasis, start: str, end: str
                    ) -> tuple[sp.csr_matrix, NDArray[np.int64]]:
    """:func:`constraint_map` computed, its arrays read-only."""
    size = basis.size
    eliminated: dict[int, NDArray[np.float64]] = {}   # coefficient -> row over all columns
    for which, preset in ((0, start), (1, end)):
        C = _end_rows(basis, which, preset)
        if C.shape[0] == 0:
            continue
        support = np.flatnonzero(np.any(C != 0, axis=0))
        order = support if which == 0 else support[::-1]   # outermost first
        r = C.shape[0]
        chosen = np.arange(r)                       # the outermost coefficients, if possible
        if np.linalg.cond(C[:, order[:r]]) > 1e8:   # otherwise the best-conditioned pivots
            chosen = np.sort(sla.qr(C[:, order], pivoting=True)[2][:r])
        E = order[chosen]
        R = np.setdiff1d(support, E)
        CE = C[:, E]
        if abs(np.linalg.det(CE)) < 1e-12 * np.abs(C).max() ** C.shape[0]:
            raise InputError(f"cannot impose a {preset} edge with degree {basis.degree} "
                             f"and {basis.cells} cell(s); refine the net")
        coupling = -np.linalg.solve(CE, C[:, R])
        for row, e in enumerate(E):
            if e in eliminated:
                raise InputError(f"the two edge conditions of a {basis.kind} basis with "
                                 f"{basis.cells} cell(s) overlap; use more cells")
            full = np.zeros(size)
            full[R] = coupling[row]
            eliminated[e] = full
    kept = np.array([j for j in range(size) if j not in eliminated], dtype=np.int64)
    T = np.zeros((size, kept.size))
    T[kept, np.arange(kept.size)] = 1.0
    for e, row in eliminated.items():
        T[e] = row[kept]
        if np.any(row[list(eliminated)] != 0):
            raise InputError("edge conditions couple eliminated coefficients; use more cells")
    T_1d = sp.csr_matrix(T)
    T_1d.has_canonical_format = True
    read_only(T_1d.data, T_1d.indices, T_1d.indptr, kept)
    return T_1d, kept


@dataclass(frozen=True)
class Constraints:
    """The map ``d = T d_free`` from free coordinates to all control points.

    Attributes
    ----------
    T : scipy.sparse.csr_matrix, shape ``(n_u n_v, n_free)``
    T_u, T_v : sparse 1-D maps, or ``None`` when a mask broke the tensor structure
    free_index : ndarray of int
        Flat index of the control point each free coordinate stands for.
    edges : dict
        The edge presets.
    masked : ``(T_u, T_v, columns)`` or ``None``
        Where fixed points leave a free region that is no rectangle: ``T = (T_u ⊗
        T_v)[:, columns]``, so ``Tᵀ A T`` is the principal submatrix ``columns`` of
        ``(T_u ⊗ T_v)ᵀ A (T_u ⊗ T_v)`` (:func:`splinedeform.assembly.masked_matrices`).
    """

    T: sp.csr_matrix
    T_u: sp.csr_matrix | None
    T_v: sp.csr_matrix | None
    free_index: NDArray[np.int64]
    edges: dict[str, str]
    has_fixed_points: bool
    masked: tuple[sp.csr_matrix, sp.csr_matrix, NDArray[np.int64]] | None = None

    @property
    def n_free(self) -> int:
        return self.T.shape[1]

    @property
    def unconstrained(self) -> bool:
        """No edge condition and no fixed control point: rigid motions are free."""
        return (all(p in ("free", "pole") for p in self.edges.values())
                and not self.has_fixed_points)


def build_constraints(basis_u: BSplineBasis, basis_v: BSplineBasis,
                      boundary: str | Mapping[str, str] = "free",
                      fixed: NDArray[np.bool_] | None = None,
                      control_points: NDArray[np.float64] | None = None) -> Constraints:
    """Assemble ``T`` from edge presets and an optional mask of fixed control points.

    Parameters
    ----------
    boundary : str or mapping
        A preset for all edges or ``{"u0": ..., "u1": ..., "v0": ..., "v1": ...}``
        (missing edges are free). ``u0`` is the edge ``u = 0``.
    fixed : bool array ``(n_u, n_v)``, optional
        ``True`` marks control points that do not move. A control point already
        determined by an edge condition follows that condition.
    control_points : array ``(n_u, n_v, 3)``, optional
        The net; given, every ``pole`` edge must be collapsed (:func:`check_poles`).
    """
    edges = edge_conditions(boundary)
    T_u, keep_u = constraint_map(basis_u, edges["u0"], edges["u1"])
    T_v, keep_v = constraint_map(basis_v, edges["v0"], edges["v1"])
    n_v = basis_v.size
    free_index = (keep_u[:, None] * n_v + keep_v[None, :]).ravel()
    mask = None if fixed is None else _check_mask(fixed, basis_u, basis_v)
    poles = [e for e, preset in edges.items() if preset == "pole"]
    if poles:
        return _with_poles(basis_u, basis_v, edges, poles, T_u, T_v, keep_u, keep_v, mask,
                           control_points)
    if mask is None:
        T = kron(T_u, T_v)
        return Constraints(T, T_u, T_v, free_index, edges, False)
    moving = ~mask[np.ix_(keep_u, keep_v)]
    rows_u, rows_v = np.any(moving, axis=1), np.any(moving, axis=0)
    rectangle = np.array_equal(moving, np.outer(rows_u, rows_v))
    if not moving.any():
        raise InputError("every control point is fixed: nothing can move")
    if rectangle:
        T_u, T_v = T_u[:, rows_u], T_v[:, rows_v]
        T = kron(T_u, T_v)
        free_index = (keep_u[rows_u][:, None] * n_v + keep_v[rows_v][None, :]).ravel()
        return Constraints(T, T_u, T_v, free_index, edges, bool(mask.any()))
    columns = np.flatnonzero(moving.ravel())
    T = kron(T_u, T_v)[:, columns]
    return Constraints(T.tocsr(), None, None, free_index[columns], edges, bool(mask.any()),
                       (T_u, T_v, columns))


def _check_mask(fixed: NDArray[np.bool_], basis_u: BSplineBasis, basis_v: BSplineBasis
                ) -> NDArray[np.bool_]:
    mask = np.asarray(fixed)
    if mask.shape != (basis_u.size, basis_v.size):
        raise InputError(f"fixed mask must have shape (n_u, n_v) = "
                         f"{(basis_u.size, basis_v.size)}, got {mask.shape}")
    if mask.dtype != bool:
        raise InputError(f"fixed mask must be boolean, got dtype {mask.dtype}")
    return mask


def _pole_rows(edge: str, basis_u: BSplineBasis, basis_v: BSplineBasis) -> NDArray[np.int64]:
    """Flat indices of the control points on a degenerate edge (clamped knots only)."""
    basis = basis_u if edge[0] == "u" else basis_v
    if not _clamped(basis, int(edge[1])):
        raise InputError(f"a pole edge ({edge}) needs open knots in {edge[0]}, or a knot vector "
                         f"clamped at that end (its control points must lie on the edge), got "
                         f"{basis.kind!r}")
    n_u, n_v = basis_u.size, basis_v.size
    line = 0 if edge[1] == "0" else (n_u if edge[0] == "u" else n_v) - 1
    if edge[0] == "u":
        return line * n_v + np.arange(n_v)
    return np.arange(n_u) * n_v + line


def _clamped(basis: BSplineBasis, end: int) -> bool:
    """Whether the spline interpolates its end coefficient at ``end`` (0 or 1): open knots,
    or a general knot vector whose end knot is repeated ``n + 1`` times."""
    if basis.kind == "open":
        return True
    if basis.kind not in ("general", "rational"):
        return False
    t, n = basis.knots, basis.degree
    return bool(t[0] == t[n]) if end == 0 else bool(t[-1] == t[-n - 1])


def _with_poles(basis_u: BSplineBasis, basis_v: BSplineBasis, edges: dict[str, str],
                poles: list[str], T_u: sp.csr_matrix, T_v: sp.csr_matrix,
                keep_u: NDArray[np.int64], keep_v: NDArray[np.int64],
                mask: NDArray[np.bool_] | None,
                control_points: NDArray[np.float64] | None) -> Constraints:
    """Merge the coordinates of each pole edge into one: ``T ← T S`` (tensor form is lost);
    the edges must be collapsed (:func:`check_poles`) when the net is given."""
    n_v = basis_v.size
    T = kron(T_u, T_v)
    points = (keep_u[:, None] * n_v + keep_v[None, :]).ravel()     # control point per column
    group = np.arange(points.size)
    for edge in poles:
        on_edge = np.flatnonzero(np.isin(points, _pole_rows(edge, basis_u, basis_v)))
        if on_edge.size:
            group[on_edge] = group[on_edge].min()
    if control_points is not None:                 # the knots are right: now the shape
        check_poles(edges, control_points)
    if mask is not None:
        # a pole moves unless all of its points are fixed
        moving = np.bincount(group, weights=~mask.ravel()[points], minlength=points.size)
        keep_group = moving[group] > 0
    else:
        keep_group = np.ones(points.size, dtype=bool)
    leaders = np.flatnonzero((group == np.arange(points.size)) & keep_group)
    if leaders.size == 0:
        raise InputError("every control point is fixed: nothing can move")
    column_of = {g: i for i, g in enumerate(leaders)}
    rows = np.flatnonzero(np.isin(group, leaders))
    S = sp.csr_matrix((np.ones(rows.size), (rows, [column_of[g] for g in group[rows]])),
                      shape=(points.size, leaders.size))
    return Constraints((T @ S).tocsr(), None, None, points[leaders], edges,
                       mask is not None and bool(mask.any()))
