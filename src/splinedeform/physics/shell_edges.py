"""Edge conditions of the Kirchhoff–Love shell as a constraint map ``d = T d_free``.

Every condition is a linear constraint on the trace of a displacement component along the
edge, or on its derivative across it, so it holds for every knot layout (open knots,
Höllig's uniform knots whose basis does not interpolate its boundary, general knot
vectors). Per component ``c`` and direction the end conditions are rows ``D^j b(x_e)`` of
the 1-D basis at the end (:func:`end_map`, as :mod:`splinedeform.boundary` does for the
plate), so component ``c`` has ``T_c = T_u^c ⊗ T_v^c`` and ``T`` interleaves the three
(dof ``3k + c``). On an edge ``x = 0`` (``∂`` across it, ``j`` the derivative orders):

- ``free``: none; ``pinned``: ``d = 0`` (``j = 0`` for x, y, z); ``clamped``: ``d = 0``
  and, on a surface in the plane ``x_a = const``, ``∂d_a = 0`` (``j = 0, 1`` for ``d_a``,
  ``j = 0`` for the in-plane components), which holds the rotation of the normal about the
  edge and leaves the membrane's in-plane slopes free; on any other surface
  ``∂d = 0`` would hold the membrane strains ``ε_nn``, ``ε_ns`` at the edge too, so there
  (``weak_rotation``: the shell's formulation, a single surface or a body's patches)
  ``T`` holds ``d = 0`` only and the rotation ``a_3·∂_n d = 0`` is Nitsche's
  (:mod:`.shell_clamp`);
- ``diaphragm`` in the plane ``x_a = const`` containing the edge and the surface normal
  (Scordelis–Lo ends): rigid in that plane, ``d_b = 0`` for ``b ≠ a``; ``d_a`` free;
- ``symmetry`` about the plane ``x_a = const``: ``d_a = 0`` and no slope across the plane,
  ``∂_ν d_b = 0`` for ``b ≠ a`` with ``ν = e_a`` in the physical frame, whatever angle the
  parameter lines make with it (:mod:`.shell_symmetry`, imposed as ``T ← T S``);
- ``pole`` (or found: an edge whose control points coincide, with open knots across it):
  the surface collapses to one point there; ``T ← T S`` ties the control points of the
  edge to one displacement (``S`` a null-space basis of ``d_k − d_k0 = 0`` on the few
  reduced coordinates involved). Other conditions on a pole are refused.

A closed (periodic) direction has no edges: conditions on it are refused. ``fixed``
components (or whole control points) remove the reduced coordinates they stand for; a
component already determined by an edge condition follows that condition.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..surface import Basis, Surface
from . import metric
from .shell_clamp import normal_axis, weak_clamps
from .shell_symmetry import slope_rows

Array = NDArray[np.float64]
EDGES = ("u0", "u1", "v0", "v1")
KINDS = ("free", "pinned", "clamped", "diaphragm", "symmetry", "pole")
SAMPLES = 9        # points per cell along an edge where its plane is measured


def check_edges(surface: Surface, boundary: Mapping[str, str]) -> dict[str, str]:
    """The four edges' kinds; unknown names, edges of closed directions refused."""
    out = {e: "free" for e in EDGES}
    for edge, kind in boundary.items():
        if edge not in EDGES or kind not in KINDS:
            raise InputError(f"shell boundary: edge must be one of {EDGES} and kind one of "
                             f"{KINDS}, got {edge!r}: {kind!r}")
        basis = surface.basis_u if edge[0] == "u" else surface.basis_v
        if kind != "free" and getattr(basis, "periodic", False):
            raise InputError(f"shell boundary {edge} = {kind!r}: the {edge[0]} direction of "
                             f"{surface.name!r} is closed (periodic knots), and a closed "
                             "direction has no edges; leave it free")
        out[edge] = kind
    poles = metric.poles(surface)
    for edge in poles:
        if out[edge] not in ("free", "pole"):
            raise InputError(f"shell boundary {edge} = {out[edge]!r}: edge {edge} of "
                             f"{surface.name!r} is a pole (its control points coincide, the "
                             "surface collapses to one point there); a pole takes 'pole' or "
                             "'free' only, and it moves as one point")
        out[edge] = "pole"
    for edge, kind in out.items():
        if kind == "pole" and edge not in poles:
            raise InputError(f"shell boundary {edge} = 'pole': the control points of edge "
                             f"{edge} of {surface.name!r} do not coincide, so it is no pole")
    return out


def _edge_parameters(surface: Surface, edge: str) -> tuple[Array, Array]:
    """Sample parameters ``(u, v)`` along an edge, ``SAMPLES`` per cell."""
    basis = surface.basis_v if edge[0] == "u" else surface.basis_u
    along = np.linspace(0.0, basis.length, SAMPLES * basis.cells + 1)
    other = surface.basis_u if edge[0] == "u" else surface.basis_v
    fixed = np.full_like(along, 0.0 if edge[1] == "0" else other.length)
    return (fixed, along) if edge[0] == "u" else (along, fixed)


def plane_axis(surface: Surface, edge: str, kind: str) -> int:
    """Axis ``a`` of the coordinate plane ``x_a = const`` of a diaphragm or symmetry edge.

    The edge curve (evaluated, so any knot layout) must lie in it; of several such planes
    (a straight edge) the one containing the surface normal is taken (the plane a
    diaphragm or a mirror stands in, across the surface).
    """
    u, v = _edge_parameters(surface, edge)
    x = surface.derivative(u, v)
    spread = np.ptp(x, axis=0)
    scale = max(1.0, float(np.abs(x).max()))
    flat = np.flatnonzero(spread <= 1e-9 * scale)
    if flat.size == 0:
        raise InputError(f"a {kind} edge must lie in a coordinate plane (x, y or z constant); "
                         f"edge {edge} of {surface.name!r} spreads {spread} in x, y, z")
    normal = np.cross(surface.derivative(u, v, 1, 0), surface.derivative(u, v, 0, 1))
    length = np.linalg.norm(normal, axis=-1)
    ok = length > 1e-9 * max(length.max(), 1e-300)
    n = normal[ok] / length[ok, None]
    tilt = np.abs(n[:, flat]).max(axis=0)           # |a_3 · e_a| for each candidate plane
    return int(flat[np.argmin(tilt)])


def end_map(basis: Basis, start: tuple[int, ...], end: tuple[int, ...]
            ) -> tuple[sp.csr_matrix, NDArray[np.int64]]:
    """1-D map ``c = T c_kept`` and the kept coefficients, with ``D^j b(x_e) · c = 0``.

    ``j`` runs over the derivative orders ``start`` (at ``x = 0``) and ``end`` (at ``L``).

    Each end's rows are solved for as many of its outermost coefficients (pivoted where
    those are ill-conditioned): ``c_E = −C_E⁻¹ C_R c_R`` (DESIGN.md §1.6, as for the plate).
    """
    size = basis.size
    eliminated: dict[int, Array] = {}
    for which, orders in ((0, start), (1, end)):
        if not orders:
            continue
        x = np.array([0.0 if which == 0 else basis.length])
        C = np.vstack([basis.matrix(x, j).toarray() for j in orders])
        support = np.flatnonzero(np.any(C != 0, axis=0))
        order = support if which == 0 else support[::-1]
        r = C.shape[0]
        chosen = np.arange(r)
        if np.linalg.cond(C[:, order[:r]]) > 1e8:
            chosen = np.sort(sla.qr(C[:, order], pivoting=True)[2][:r])
        E = order[chosen]
        R = np.setdiff1d(support, E)
        if np.linalg.cond(C[:, E]) > 1e12 or np.intersect1d(E, list(eliminated)).size:
            raise InputError(f"cannot impose these edge conditions with degree "
                             f"{basis.degree} and {basis.cells} cell(s); use more cells "
                             "(a CAD surface: insert knots, surface.refine)")
        coupling = -np.linalg.solve(C[:, E], C[:, R])
        for row, e in enumerate(E):
            full = np.zeros(size)
            full[R] = coupling[row]
            eliminated[int(e)] = full
    kept = np.array([j for j in range(size) if j not in eliminated], dtype=np.int64)
    T = np.zeros((size, kept.size))
    T[kept, np.arange(kept.size)] = 1.0
    for e, row in eliminated.items():
        if np.any(row[list(eliminated)] != 0):
            raise InputError("the edge conditions of the two ends overlap; use more cells (a CAD "
                             "surface: insert knots, surface.refine)")
        T[e] = row[kept]
    return sp.csr_matrix(T), kept


def _orders(kind: str, axis: int | None, c: int) -> tuple[int, ...]:
    """Derivative orders across the edge constrained for component ``c`` (``axis``: the
    plane's for a diaphragm or symmetry edge, the surface's normal axis for a clamped one,
    ``None`` there: every component's slope)."""
    if kind == "pinned":
        return (0,)
    if kind == "clamped":
        return (0, 1) if axis is None or c == axis else (0,)
    if kind == "diaphragm":
        return () if c == axis else (0,)
    if kind == "symmetry":
        return (0,) if c == axis else ()      # the slope: shell_symmetry.slope_rows
    return ()


def constraint_matrix(surface: Surface, boundary: Mapping[str, str],
                      fixed: Array | None = None, weak_rotation: bool = False,
                      alone: bool = True) -> sp.csr_matrix:
    """``T`` with ``d = T d_free`` over the interleaved ``3n`` displacements (module doc);
    with ``weak_rotation`` a curved surface's clamped edges are pinned, their rotation left
    to :func:`.shell_clamp.clamp_rotation` (else the whole slope is held). A surface
    ``alone`` must keep a free displacement; a body's patch (``alone=False``) may be held
    whole, its neighbours moving."""
    edges = check_edges(surface, boundary)
    weak = weak_clamps(surface, edges) if weak_rotation else ()
    kinds = {**edges, **{e: "pinned" for e in weak}}
    n_u, n_v = surface.shape
    n = n_u * n_v
    is_fixed = np.zeros(3 * n, bool)
    if fixed is not None:
        mask = np.asarray(fixed, bool)
        if mask.shape == surface.shape:          # whole control points, as for Model
            mask = np.repeat(mask[..., None], 3, axis=-1)
        is_fixed = mask.ravel().copy()
    if is_fixed.size != 3 * n:
        raise InputError(f"fixed must be a boolean mask of shape {surface.shape} (control "
                         f"points) or {surface.shape + (3,)} (components)")
    axes: dict[str, int | None] = {e: None for e in EDGES}
    for edge, kind in edges.items():
        if kind in ("diaphragm", "symmetry"):
            axes[edge] = plane_axis(surface, edge, kind)
        elif kind == "clamped" and weak_rotation:
            axes[edge] = normal_axis(surface)          # None: a weak clamp, pinned here
    blocks, dofs = [], []
    for c in range(3):
        T_u, keep_u = end_map(surface.basis_u,
                              *(_orders(kinds[e], axes[e], c) for e in ("u0", "u1")))
        T_v, keep_v = end_map(surface.basis_v,
                              *(_orders(kinds[e], axes[e], c) for e in ("v0", "v1")))
        blocks.append(sp.kron(T_u, T_v, format="csr"))
        dofs.append(3 * (keep_u[:, None] * n_v + keep_v[None, :]).ravel() + c)
    T = _interleave(blocks, np.concatenate(dofs), n)
    T = T[:, ~is_fixed[np.sort(np.concatenate(dofs))]].tocsr()
    for edge in (e for e, kind in edges.items() if kind == "symmetry"):
        T = _impose(T, slope_rows(surface, edge, axes[edge]) @ T)
    for edge in (e for e, kind in edges.items() if kind == "pole"):
        T = _impose(T, _pole_rows(T, surface, edge))
    if T.shape[1] == 0 and alone:
        raise InputError("the shell's boundary conditions and fixed components leave no "
                         "displacement free")
    return T


def _interleave(blocks: list[sp.csr_matrix], dofs: NDArray[np.int64], n: int
                ) -> sp.csr_matrix:
    """Rows ``k`` of block ``c`` become dof ``3k + c``; columns ordered by the dof they keep."""
    rows, cols, vals = [], [], []
    offset = 0
    for c, B in enumerate(blocks):
        coo = B.tocoo()
        rows.append(3 * coo.row + c)
        cols.append(coo.col + offset)
        vals.append(coo.data)
        offset += B.shape[1]
    new = np.empty(offset, dtype=np.int64)
    new[np.argsort(dofs, kind="stable")] = np.arange(offset)
    T = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), new[np.concatenate(cols)])),
                      shape=(3 * n, offset))
    T.eliminate_zeros()
    return T


def _pole_rows(T: sp.csr_matrix, surface: Surface, edge: str) -> sp.csc_matrix:
    """Rows ``(T_k − T_k0) x = 0`` over the reduced coordinates: one point on the pole."""
    n_u, n_v = surface.shape
    grid = np.arange(n_u * n_v).reshape(n_u, n_v)
    points = {"u0": grid[0], "u1": grid[-1], "v0": grid[:, 0], "v1": grid[:, -1]}[edge]
    dofs = 3 * points[:, None] + np.arange(3)                    # (points, 3)
    return sp.vstack([T[dofs[1:, c]] - T[np.full(len(points) - 1, dofs[0, c])]
                      for c in range(3)]).tocsc()


def _impose(T: sp.csr_matrix, A: sp.spmatrix) -> sp.csr_matrix:
    """``T S`` with ``range S = null A`` (``A`` over the reduced coordinates ``x``).

    Only the columns ``A`` touches change: ``S`` is the identity on the others and a dense
    null-space basis (SVD, rank-revealing) on the few involved.
    """
    A = sp.csc_matrix(A)
    involved = np.flatnonzero(np.diff(A.indptr))
    if involved.size == 0:
        return T
    dense = A[:, involved].toarray()
    null = sla.null_space(dense, rcond=1e-10)                    # (involved, kept)
    null[np.abs(null) < 1e-14] = 0.0
    others = np.setdiff1d(np.arange(T.shape[1]), involved)
    S = sp.hstack([sp.csr_matrix((np.ones(others.size), (others, np.arange(others.size))),
                                 shape=(T.shape[1], others.size)),
                   sp.csr_matrix((null.ravel(), (np.repeat(involved, null.shape[1]),
                                                 np.tile(np.arange(null.shape[1]),
                                                         involved.size))),
                                 shape=(T.shape[1], null.shape[1]))]).tocsr()
    return (T @ S).tocsr()
