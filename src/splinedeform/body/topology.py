"""Interfaces found geometrically: which patch edges meet, how, and whether they conform.

Each edge of a non-periodic direction (``u0``, ``u1``, ``v0``, ``v1``, see
:mod:`.interface`) is sampled at ``SAMPLES`` equally spaced fractions of its parameter
interval. With the body's size ``D`` (the diagonal of its bounding box) and the tolerance
``tol = TOLERANCE · D`` unless given:

* an edge whose samples all lie within ``tol`` of its first one is **degenerate** (a pole);
* two edges **meet** when their end points coincide (``|x_a − x_b| <= tol``, a k-d tree
  over all end points) and every sample of each lies within ``tol`` of the other curve:
  at the same fractions (``aligned``: the parametrisations agree after the affine map of
  the two intervals, mirrored when ``reversed``), else by projecting the samples onto the
  other edge (Newton's method on ``|c(s) − x|²`` from the nearest of a dense sample);
* the edge of a patch that meets another edge of the same patch is a **seam**;
* three or more edges on one curve make a **non-manifold** edge;
* an edge no other edge meets is a **boundary** edge.

An interface **conforms** when its control points can be merged: aligned, the same degree
and knots along the edge (normalised to ``[0, 1]``, mirrored when reversed), both patches
interpolating their edge control points (knots clamped at that end), the two rows of edge
control points within ``tol`` of each other and NURBS weights along the edge proportional.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..boundary import _clamped, edge_points
from ..errors import InputError
from ..surface import Surface
from .interface import EDGES, Interface

Array = NDArray[np.float64]
TOLERANCE = 1e-6
"""Default matching distance as a fraction of the body's bounding-box diagonal."""
SAMPLES = 9
"""Samples per edge (equally spaced in its parameter, ends included)."""
KNOT_TOLERANCE = 1e-10
"""Normalised knots closer than this are one knot (round-off of a file)."""

Edge = tuple[int, str]


@dataclass(frozen=True)
class Topology:
    """What :func:`find_topology` found.

    Attributes
    ----------
    interfaces : tuple of Interface
        Every pair of edges that meet (shared edges and seams; each pair of a non-manifold
        edge too).
    aligned : tuple of bool
        Per interface: the two parametrisations agree after the affine map (what exact knot
        insertion needs to make it conform).
    boundary : tuple of (patch, edge)
        Edges no other edge meets.
    poles : tuple of (patch, edge)
        Degenerate edges (collapsed to a point).
    non_manifold : tuple of tuple of (patch, edge)
        The edges of each curve where three or more meet.
    tol : float
        The matching distance used.
    """

    interfaces: tuple[Interface, ...]
    aligned: tuple[bool, ...]
    boundary: tuple[Edge, ...]
    poles: tuple[Edge, ...]
    non_manifold: tuple[tuple[Edge, ...], ...]
    tol: float

    def summary(self) -> dict[str, int]:
        """Counts: ``shared`` edges (two patches), ``seam``, ``boundary``, ``non_manifold``
        curves, ``poles``, ``non_conforming`` interfaces."""
        in_groups = {edge for group in self.non_manifold for edge in group}
        manifold = [i for i in self.interfaces if (i.a, i.edge_a) not in in_groups]
        return {"shared": sum(i.a != i.b for i in manifold),
                "seam": sum(i.a == i.b for i in manifold),
                "boundary": len(self.boundary),
                "non_manifold": len(self.non_manifold),
                "poles": len(self.poles),
                "non_conforming": sum(not i.conforming for i in self.interfaces)}


def edges_of(surface: Surface) -> list[str]:
    """The edges of a patch: those of its non-periodic directions."""
    return [e for e in EDGES if not (surface.basis_u if e[0] == "u" else surface.basis_v).periodic]


def edge_parameters(surface: Surface, edge: str, s: Array) -> tuple[Array, Array]:
    """Parameters ``(u, v)`` of the points at edge parameter ``s`` along ``edge``."""
    (_, lu), (_, lv) = surface.domain
    s = np.asarray(s, dtype=float)
    fixed = np.full(s.shape, {"u0": 0.0, "u1": lu, "v0": 0.0, "v1": lv}[edge])
    return (fixed, s) if edge[0] == "u" else (s, fixed)


def edge_length(surface: Surface, edge: str) -> float:
    """Length of the parameter interval along ``edge``."""
    return (surface.basis_v if edge[0] == "u" else surface.basis_u).length


def edge_basis(surface: Surface, edge: str) -> object:
    """The 1-D basis along ``edge`` (``v``'s for ``u0``/``u1``)."""
    return surface.basis_v if edge[0] == "u" else surface.basis_u


def sample_edge(surface: Surface, edge: str, count: int = SAMPLES) -> Array:
    """``count`` points at equally spaced parameters along ``edge`` (ends included)."""
    s = np.linspace(0.0, edge_length(surface, edge), count)
    return surface.evaluate(*edge_parameters(surface, edge, s))


def body_size(surfaces: Sequence[Surface], resolution: int = 17) -> tuple[Array, Array]:
    """Bounding box ``(lower, upper)`` of the patches sampled on ``resolution²`` grids."""
    points = np.concatenate([s.evaluate_grid(*s.sample_parameters(resolution)).reshape(-1, 3)
                             for s in surfaces])
    return points.min(axis=0), points.max(axis=0)


def _project(surface: Surface, edge: str, x: Array) -> Array:
    """Distance of each point ``x`` (P, 3) to the curve ``edge`` of ``surface``."""
    L = edge_length(surface, edge)
    basis = edge_basis(surface, edge)
    dense = np.linspace(0.0, L, 16 * basis.cells + 1)
    curve = surface.evaluate(*edge_parameters(surface, edge, dense))
    s = dense[np.argmin(np.linalg.norm(x[:, None] - curve[None], axis=-1), axis=1)]
    order = (0, 1) if edge[0] == "u" else (1, 0)        # derivative along the edge
    for _ in range(8):                                   # Newton on |c(s) - x|²
        u, v = edge_parameters(surface, edge, s)
        r = surface.evaluate(u, v) - x
        d1 = surface.derivative(u, v, *order)
        d2 = surface.derivative(u, v, *(2 * o for o in order)) \
            if basis.degree >= 2 else np.zeros_like(d1)
        slope = np.sum(r * d1, axis=1)
        curvature = np.sum(d1 * d1, axis=1) + np.sum(r * d2, axis=1)
        step = np.where(curvature > 0, slope / np.where(curvature > 0, curvature, 1.0), 0.0)
        s = np.clip(s - step, 0.0, L)
    return np.linalg.norm(surface.evaluate(*edge_parameters(surface, edge, s)) - x, axis=1)


def normalised_knots(basis: Any, mirrored: bool) -> Array:
    """The knot vector of ``basis`` over its length, ``t / L`` (mirrored: ``1 − t/L`` reversed)."""
    t = np.asarray(basis.knots, dtype=float) / basis.length
    return 1.0 - t[::-1] if mirrored else t


def _weights(surface: Surface, edge: str) -> Array:
    return edge_points(surface.weights[..., None], edge)[:, 0]


def conforming(sa: Surface, ea: str, sb: Surface, eb: str, reversed_: bool, tol: float) -> bool:
    """Whether the control points of the two edges can be merged (module docstring)."""
    ba, bb = edge_basis(sa, ea), edge_basis(sb, eb)
    if ba.degree != bb.degree or ba.size != bb.size:      # type: ignore[attr-defined]
        return False
    ta, tb = normalised_knots(ba, False), normalised_knots(bb, reversed_)
    if ta.shape != tb.shape or np.max(np.abs(ta - tb)) > KNOT_TOLERANCE:
        return False
    for surface, edge in ((sa, ea), (sb, eb)):
        across = surface.basis_u if edge[0] == "u" else surface.basis_v
        if across.periodic or not _clamped(across, int(edge[1])):
            return False
    pa, pb = edge_points(sa.control_points, ea), edge_points(sb.control_points, eb)
    wa, wb = _weights(sa, ea), _weights(sb, eb)
    if reversed_:
        pb, wb = pb[::-1], wb[::-1]
    ratio = wa / wb
    return bool(np.max(np.linalg.norm(pa - pb, axis=1)) <= tol
                and np.ptp(ratio) <= 1e-12 * ratio.max())


def find_topology(surfaces: Sequence[Surface], tol: float | None = None) -> Topology:
    """Interfaces, boundary edges, poles and non-manifold edges of a set of patches.

    Parameters
    ----------
    surfaces : sequence of Surface
    tol : float, optional
        Matching distance; default ``TOLERANCE ×`` the bounding-box diagonal.
    """
    surfaces = list(surfaces)
    if not surfaces or not all(isinstance(s, Surface) for s in surfaces):
        raise InputError("a body needs a non-empty list of splinedeform.Surface patches")
    if tol is None:
        lower, upper = body_size(surfaces)
        tol = TOLERANCE * float(np.linalg.norm(upper - lower))
    tol = float(tol)
    if not np.isfinite(tol) or tol <= 0:
        raise InputError(f"the matching tolerance must be finite and > 0, got {tol}")
    edges: list[Edge] = [(p, e) for p, s in enumerate(surfaces) for e in edges_of(s)]
    samples = np.array([sample_edge(surfaces[p], e) for p, e in edges]).reshape(-1, SAMPLES, 3)
    spread = np.max(np.linalg.norm(samples - samples[:, :1], axis=-1), axis=1)
    degenerate = spread <= tol
    live = np.flatnonzero(~degenerate)
    ends = samples[live][:, [0, -1]].reshape(-1, 3)            # start, end of each live edge
    pairs = cKDTree(ends).query_pairs(tol, output_type="ndarray") if ends.size else \
        np.zeros((0, 2), dtype=np.int64)
    links = {(int(live[p // 2]), int(live[q // 2]), p % 2, q % 2) for p, q in pairs}
    links |= {(j, i, b, a) for i, j, a, b in links}
    matches: list[tuple[int, int, bool, bool]] = []          # (i, j, reversed, aligned)
    for i, j in sorted({(i, j) for i, j, _, _ in links if i < j}):
        options = [rev for rev, ok in ((False, ((0, 0), (1, 1))), (True, ((0, 1), (1, 0))))
                   if all((i, j, a, b) in links for a, b in ok)]
        gaps = [np.max(np.linalg.norm(samples[i] - (samples[j][::-1] if rev else samples[j]),
                                      axis=1)) for rev in options]
        if gaps and min(gaps) <= tol:           # the parametrisations agree: aligned
            matches.append((i, j, options[int(np.argmin(gaps))], True))
        elif options and _coincide(surfaces, edges[i], edges[j], samples[i], samples[j], tol):
            matches.append((i, j, options[0], False))
    interfaces, aligned_flags = [], []
    for i, j, rev, aligned in matches:
        (a, ea), (b, eb) = edges[i], edges[j]
        conform = aligned and conforming(surfaces[a], ea, surfaces[b], eb, rev, tol)
        interfaces.append(Interface(a, ea, b, eb, rev, conform))
        aligned_flags.append(aligned)
    n = len(edges)
    rows = [m[0] for m in matches]
    cols = [m[1] for m in matches]
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    sizes = np.bincount(label, minlength=n)
    groups = [tuple(edges[k] for k in np.flatnonzero(label == g))
              for g in np.flatnonzero(sizes >= 3)]
    matched = set(rows) | set(cols)
    boundary = tuple(edges[k] for k in live if k not in matched)
    poles = tuple(edges[k] for k in np.flatnonzero(degenerate))
    return Topology(tuple(interfaces), tuple(aligned_flags), boundary, poles, tuple(groups), tol)


def _coincide(surfaces: Sequence[Surface], edge_i: Edge, edge_j: Edge, xi: Array, xj: Array,
              tol: float) -> bool:
    """Whether the samples of each edge lie within ``tol`` of the other curve."""
    (a, ea), (b, eb) = edge_i, edge_j
    return bool(_project(surfaces[b], eb, xi).max() <= tol
                and _project(surfaces[a], ea, xj).max() <= tol)


def find_interfaces(surfaces: Sequence[Surface], tol: float | None = None) -> list[Interface]:
    """The interfaces of :func:`find_topology` (shared edges, seams, non-manifold pairs).

    Examples
    --------
    >>> import splinedeform as sd
    >>> left = sd.shapes.plane(size=(0.5, 1.0), cells=(2, 2))
    >>> right = left.with_control_points(left.control_points + [0.5, 0, 0])
    >>> sd.find_interfaces([left, right])
    [Interface(a=0, edge_a='u1', b=1, edge_b='u0', reversed=False, conforming=True)]
    """
    return list(find_topology(surfaces, tol).interfaces)
