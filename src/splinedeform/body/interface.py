"""An interface: where an edge of one patch meets an edge of another (or of itself).

Edges are named as everywhere in the package: ``u0`` is the edge ``u = u_min`` (it runs
along v), ``u1`` is ``u = u_max``, ``v0`` is ``v = v_min`` (it runs along u), ``v1`` is
``v = v_max``.  Along the shared curve, edge ``a`` at its parameter ``s`` meets edge ``b`` at
``s`` (``reversed = False``) or at the opposite end's ``s`` (``reversed = True``), both edges'
parameters taken in increasing order.
"""

from __future__ import annotations

from dataclasses import dataclass

EDGES = ("u0", "u1", "v0", "v1")


@dataclass(frozen=True)
class Interface:
    """Edge ``edge_a`` of patch ``a`` meets edge ``edge_b`` of patch ``b``.

    Attributes
    ----------
    a, b : int
        Patch indices in the body (``a == b`` for a seam of a closed patch).
    edge_a, edge_b : str
        ``"u0" | "u1" | "v0" | "v1"``.
    reversed : bool
        Whether ``b``'s edge parameter runs opposite to ``a``'s along the curve.
    conforming : bool
        Whether both edges have the same degree and knots (after aligning the parameters
        and, if reversed, mirroring them), so that their control points can be merged.
    """

    a: int
    edge_a: str
    b: int
    edge_b: str
    reversed: bool = False
    conforming: bool = True

    def __post_init__(self) -> None:
        for edge in (self.edge_a, self.edge_b):
            if edge not in EDGES:
                raise ValueError(f"an edge is one of {EDGES}, got {edge!r}")
        if self.a == self.b and self.edge_a == self.edge_b:
            raise ValueError(f"an interface joins two different edges, got {self.edge_a} twice "
                             f"on patch {self.a}")


@dataclass(frozen=True)
class TrimInterface:
    """Trim loop ``loop_a`` of face ``a`` meets trim loop ``loop_b`` of face ``b`` along one
    curve (loops counted as in :attr:`splinedeform.trim.TrimDomain.loops`: 0 the outer
    loop, then the holes); coupled by :func:`splinedeform.physics.coupling_curves.curve_penalty`.
    """

    a: int
    loop_a: int
    b: int
    loop_b: int

    def __str__(self) -> str:
        return (f"the trim interface of face {self.a} loop {self.loop_a} and face {self.b} "
                f"loop {self.loop_b}")


@dataclass(frozen=True)
class TrimEdgeInterface:
    """Edge ``edge_a`` of face ``a`` meets edge ``edge_b`` of face ``b`` along a common
    stretch of both: the parameters ``part_a`` of ``a``'s curve and ``part_b`` of ``b``'s.

    An edge is a trim edge (``outer``, ``hole1`` for a loop of one edge; ``outer.2`` for
    edge 2 of a loop of several, as a boundary mapping names them) or an iso-edge of the
    face's rectangle (``u0`` …). The curve of a trim edge is its loop (parameters as in
    :func:`splinedeform.physics.coupling_curves.period`); that of an iso-edge the
    rectangle's polygon ``(0, 0), (L_u, 0), (L_u, L_v), (0, L_v)`` (``v0`` is
    ``t ∈ [0, 1]``, ``u1`` ``[1, 2]``, ``v1`` ``[2, 3]``, ``u0`` ``[3, 4]``). Found by
    :func:`splinedeform.body.trim_edges.find_edge_interfaces`.
    """

    a: int
    edge_a: str
    part_a: tuple[float, float]
    b: int
    edge_b: str
    part_b: tuple[float, float]

    def __str__(self) -> str:
        return (f"the shared trim edge of face {self.a} edge {self.edge_a} and face {self.b} "
                f"edge {self.edge_b}")
