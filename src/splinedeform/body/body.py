"""A body: patches and the interfaces between their edges.

``Body(patches)`` finds its interfaces geometrically (:mod:`.topology`) unless they are
given (e.g. from a CAD file's topology); poles and boundary edges are always found from the
geometry. :meth:`Body.conforming` makes interfaces whose two sides have the same degree but
different knots conform by exact knot insertion (Boehm's algorithm, :mod:`splinedeform.refine`):
on each side the knots of the other side that it lacks (normalised to ``[0, 1]``, mirrored
when reversed, with the larger multiplicity) are inserted, and since inserting knots into a
direction changes every edge along it, this is repeated until nothing is left to insert.
The geometry does not move (``P' = T (a P) / a'`` in homogeneous coordinates).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Iterator, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..basis import BSplineBasis
from ..errors import InputError
from ..knots import KnotVectorBasis, RationalBasis
from ..refine import boehm_insert
from ..surface import Surface
from .interface import Interface, TrimEdgeInterface, TrimInterface
from .topology import (KNOT_TOLERANCE, Topology, body_size, edge_basis, edges_of,
                       find_topology, normalised_knots)
from .trim_edges import find_edge_interfaces, iso_stretches, labelled, trim_edge_summary
from .trimmed import (checked_trim_interfaces, find_trim_interfaces, unmerged_at_trims,
                      without_trimmed_edges)

Array = NDArray[np.float64]
MAX_PASSES = 16
"""Most rounds of knot insertion :meth:`Body.conforming` makes."""


class Body:
    """Patches deformed as one connected surface.

    Parameters
    ----------
    patches : list of Surface
    interfaces : list of Interface, optional
        Where edges meet; found geometrically (:func:`~.topology.find_topology`) if not given.
    tol : float, optional
        Matching distance (default ``1e-6 ×`` the bounding-box diagonal).
    trim_interfaces : list of TrimInterface, optional
        Trim loops of two faces that meet along one curve; found geometrically
        (:func:`~.trimmed.find_trim_interfaces`) if not given.
    orientation : sequence of {+1, -1}, optional
        Per patch the sign ``s`` that makes ``s x_u × x_v`` the body's normal (a CAD face
        marked reversed in its Brep has ``-1``); a pressure pushes along it. Default: each
        patch's own :attr:`~splinedeform.Surface.orientation` (``+1`` unless it was read
        reversed). The parametrisations are left as they are.

    Trimmed faces (``surface.trim``) meet along their trim curves: pairs of loops tracing
    one curve are found geometrically (:mod:`.trimmed`), :attr:`trim_interfaces`; then
    the trim edges of the other loops with each other and with the boundary iso-edges of
    other faces, in whole or in part (:mod:`.trim_edges`), :attr:`edge_interfaces`; and
    boundary iso-edges of any faces with each other where they share only a stretch (a
    T-junction: a face's edge along part of a neighbour's, trimmed or not). An
    iso-edge shared that way is no boundary edge, and an iso-edge interface of a trimmed
    face (a rectangle with holes) is coupled by penalties, not merged.

    Examples
    --------
    >>> import splinedeform as sd
    >>> left = sd.shapes.plane(size=(0.5, 1.0), cells=(2, 2))
    >>> right = left.with_control_points(left.control_points + [0.5, 0, 0])
    >>> body = sd.Body([left, right])
    >>> body.summary()["shared"], body.summary()["boundary"]
    (1, 6)
    """

    def __init__(self, patches: Sequence[Surface], interfaces: Sequence[Interface] | None = None,
                 tol: float | None = None,
                 trim_interfaces: Sequence[TrimInterface] | None = None,
                 orientation: Sequence[int] | None = None):
        self.patches: tuple[Surface, ...] = tuple(
            labelled(s) if isinstance(s, Surface) else s for s in patches)
        self.orientation: tuple[int, ...] = _orientation(
            [getattr(s, "orientation", 1) for s in self.patches] if orientation is None
            else orientation, len(self.patches))
        found = without_trimmed_edges(self.patches, find_topology(self.patches, tol))
        if interfaces is None:
            self.topology = found
        else:
            self.topology = _given(self.patches, list(interfaces), found)
        self.interfaces: tuple[Interface, ...] = self.topology.interfaces
        self.trim_interfaces: tuple[TrimInterface, ...] = (
            checked_trim_interfaces(self.patches, trim_interfaces)
            if trim_interfaces is not None
            else find_trim_interfaces(self.patches, self.topology.tol)
            if any(s.trim is not None for s in self.patches) else ())
        topology = unmerged_at_trims(self.patches, self.topology)
        whole = {(i.a, i.loop_a) for i in self.trim_interfaces} | {
            (i.b, i.loop_b) for i in self.trim_interfaces}
        self.edge_interfaces: tuple[TrimEdgeInterface, ...] = find_edge_interfaces(
            self.patches, topology.boundary, whole, topology.tol)
        iso = {(i.a, i.edge_a) for i in self.edge_interfaces} | {
            (i.b, i.edge_b) for i in self.edge_interfaces}
        self.topology = replace(topology, boundary=tuple(
            e for e in topology.boundary if e not in iso))
        self.interfaces = self.topology.interfaces

    @classmethod
    def from_surfaces(cls, surfaces: Sequence[Surface], tol: float | None = None) -> Body:
        """A body of ``surfaces`` with its interfaces found geometrically."""
        return cls(surfaces, None, tol)

    def __len__(self) -> int:
        return len(self.patches)

    def __iter__(self) -> Iterator[Surface]:
        return iter(self.patches)

    def __getitem__(self, index: int) -> Surface:
        return self.patches[index]

    def __repr__(self) -> str:
        counts = ", ".join(f"{k}={v}" for k, v in self.summary().items())
        return f"Body({len(self.patches)} patches, {counts})"

    def summary(self) -> dict[str, int]:
        """Counts of shared edges, seams, boundary edges, non-manifold edges, poles and
        non-conforming interfaces (:meth:`~.topology.Topology.summary`), and where two
        iso-edges share only a stretch (a T-junction, :mod:`.trim_edges`) their count,
        ``partly_shared``."""
        counts = self.topology.summary()
        partly = iso_stretches(self.edge_interfaces)
        return {**counts, "partly_shared": len(partly)} if partly else counts

    def trim_summary(self) -> dict[str, int]:
        """Counts of the trim edges of the body's trimmed faces: ``shared`` with another
        face (in whole or in part), ``free``, and the coupled ``stretches``
        (:func:`~.trim_edges.trim_edge_summary`)."""
        return trim_edge_summary(self.patches, self.trim_interfaces, self.edge_interfaces)

    def evaluate(self, patch: int, u: ArrayLike, v: ArrayLike) -> Array:
        """Points ``x(u, v)`` of patch ``patch`` (:meth:`Surface.evaluate`)."""
        return self.patches[self._index(patch)].evaluate(u, v)

    def _index(self, patch: int) -> int:
        if not isinstance(patch, (int, np.integer)) or not 0 <= patch < len(self.patches):
            raise InputError(f"patch must be an index in [0, {len(self.patches) - 1}], "
                             f"got {patch!r}")
        return int(patch)

    def bounding_box(self) -> tuple[Array, Array]:
        """``(lower, upper)`` corners of the patches sampled on ``17 × 17`` grids."""
        return body_size(self.patches)

    def conforming(self) -> Body:
        """The same body with every interface of equal degrees made conforming by exact knot
        insertion (module docstring); interfaces of different degrees stay as they are,
        and so do those of trimmed faces (coupled by penalties, never merged)."""
        patches = list(self.patches)
        trims = {p for p, s in enumerate(patches) if s.trim is not None}
        for _ in range(MAX_PASSES):
            topology = find_topology(patches, self.topology.tol)
            if not insert_missing_knots(patches, [
                    i for i, aligned in zip(topology.interfaces, topology.aligned)
                    if aligned and not i.conforming and not {i.a, i.b} & trims]):
                return Body(patches, None, self.topology.tol, orientation=self.orientation)
        raise InputError(f"knot insertion did not make the interfaces conform in {MAX_PASSES} "
                         "rounds; refine the patches to common knots")


def insert_missing_knots(patches: list[Surface], interfaces: Sequence[Interface]) -> bool:
    """One round of :meth:`Body.conforming` on ``interfaces``: into each side of each the
    knots of the other side that it lacks, ``patches`` replaced in place; whether any knot
    was inserted (a direction's new knots change every edge along it: repeat until none)."""
    wanted: dict[tuple[int, str], list[list[float]]] = {}
    for interface in interfaces:
        sides = ((interface.a, interface.edge_a, interface.b, interface.edge_b),
                 (interface.b, interface.edge_b, interface.a, interface.edge_a))
        for p, e, q, f in sides:
            missing = _missing(edge_basis(patches[p], e), edge_basis(patches[q], f),
                               interface.reversed)
            if missing:
                wanted.setdefault((p, "v" if e[0] == "u" else "u"), []).append(missing)
    for (p, direction), values in wanted.items():
        patches[p] = insert_knots_at(patches[p], direction, _distinct(values))
    return bool(wanted)


def _orientation(signs: Sequence[int] | None, count: int) -> tuple[int, ...]:
    """``signs`` checked as one ``+1`` or ``-1`` per patch (``+1`` each when None)."""
    if signs is None:
        return (1,) * count
    out = tuple(signs)
    if len(out) != count or any(isinstance(s, bool) or s not in (1, -1) for s in out):
        raise InputError(f"orientation must be one sign, +1 or -1, per patch ({count}), "
                         f"got {list(out)!r}")
    return tuple(int(s) for s in out)


def _given(patches: tuple[Surface, ...], interfaces: list[Interface], found: Topology
           ) -> Topology:
    """A topology with the given interfaces; poles and boundary edges from the geometry."""
    for i in interfaces:
        if not isinstance(i, Interface):
            raise InputError(f"interfaces must be splinedeform.body.Interface records, got "
                             f"{type(i).__name__}")
        for p, e in ((i.a, i.edge_a), (i.b, i.edge_b)):
            if not 0 <= p < len(patches) or e not in edges_of(patches[p]):
                raise InputError(f"interface {i} names edge {e} of patch {p}, which the body "
                                 f"of {len(patches)} patches does not have")
    used = {(i.a, i.edge_a) for i in interfaces} | {(i.b, i.edge_b) for i in interfaces}
    boundary = tuple(edge for edge in found.boundary + tuple(
        edge for i in found.interfaces for edge in ((i.a, i.edge_a), (i.b, i.edge_b)))
        if edge not in used)
    aligned = tuple(i.conforming for i in interfaces)
    return Topology(tuple(interfaces), aligned, tuple(dict.fromkeys(boundary)), found.poles,
                    found.non_manifold, found.tol)


def _multiplicities(basis: object, mirrored: bool) -> dict[float, int]:
    t = normalised_knots(basis, mirrored)
    inner = t[(t > KNOT_TOLERANCE) & (t < 1.0 - KNOT_TOLERANCE)]
    values, counts = np.unique(np.round(inner / KNOT_TOLERANCE) * KNOT_TOLERANCE,
                               return_counts=True)
    return dict(zip(values.tolist(), counts.tolist()))


def _missing(mine: object, other: object, reversed_: bool) -> list[float]:
    """Knots of ``other`` (in ``mine``'s parameter) that ``mine`` lacks, with multiplicity."""
    have, want = _multiplicities(mine, False), _multiplicities(other, reversed_)
    length = mine.length  # type: ignore[attr-defined]
    out: list[float] = []
    for x, count in want.items():
        near = [k for k in have if abs(k - x) <= 10 * KNOT_TOLERANCE]
        extra = count - (have[near[0]] if near else 0)
        out += [(near[0] if near else x) * length] * max(extra, 0)
    return out


def _distinct(requests: list[list[float]]) -> list[float]:
    """The knots asked for by several interfaces along one direction: each value with the
    largest multiplicity any of them asks for."""
    largest: dict[float, tuple[float, int]] = {}
    for values in requests:
        rounded = np.round(np.asarray(values) / KNOT_TOLERANCE) * KNOT_TOLERANCE
        keys, first, counts = np.unique(rounded, return_index=True, return_counts=True)
        for key, i, count in zip(keys.tolist(), first, counts):
            if count > largest.get(key, (0.0, 0))[1]:
                largest[key] = (float(values[i]), int(count))
    return [x for x, count in largest.values() for _ in range(count)]


def insert_knots_at(surface: Surface, direction: str, values: Sequence[float]) -> Surface:
    """``surface`` with the knots ``values`` inserted in ``direction`` (exactly, Boehm).

    The direction must have a knot vector clamped at both ends (open or general knots,
    polynomial or rational); a rational one is refined in homogeneous coordinates.
    """
    axis = 0 if direction == "u" else 1
    basis = surface.basis_u if axis == 0 else surface.basis_v
    weights = basis.weights if isinstance(basis, RationalBasis) else None
    poly = basis.basis if isinstance(basis, RationalBasis) else basis
    if isinstance(poly, BSplineBasis) and poly.kind != "open":
        raise InputError(f"knots can be inserted into open or general knot vectors only; "
                         f"direction {direction} of {surface.name!r} is {poly.kind!r}")
    a = np.ones(poly.size) if weights is None else np.asarray(weights)
    P = np.moveaxis(np.asarray(surface.control_points), axis, 0)       # (n, m, 3)
    w = np.broadcast_to(a[:, None, None], P.shape[:2] + (1,)) if surface.net_weights is None \
        else np.moveaxis(surface.net_weights, axis, 0)[..., None]      # general weights
    coefficients = np.concatenate([P * w, w], axis=2)
    knots = np.asarray(poly.knots, dtype=float)
    for x in sorted(values):
        knots, coefficients = boehm_insert(knots, poly.degree, float(x), coefficients)
    new_weights = coefficients[:, 0, 3]
    new_points = coefficients[..., :3] / coefficients[..., 3:]
    net_weights = None if surface.net_weights is None \
        else np.moveaxis(coefficients[..., 3], 0, axis)
    new: object = KnotVectorBasis(poly.degree, knots)
    if weights is not None:
        new = RationalBasis(new, new_weights)  # type: ignore[arg-type]
    bases = (new, surface.basis_v) if axis == 0 else (surface.basis_u, new)
    return Surface(np.moveaxis(new_points, 0, axis), bases[0], bases[1], name=surface.name,
                   net_weights=net_weights)
