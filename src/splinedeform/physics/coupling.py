"""Weak coupling of patches across an interface: displacement and rotation penalties.

Two patches ``a`` and ``b`` meet along a curve ``Γ`` (an :class:`~splinedeform.body.Interface`,
or a ``C^0`` knot line inside one patch, whose two sides meet there). Where their control
points cannot be merged (different knots or degrees along ``Γ``) the displacement jump is
penalised (Herrema et al., CMAME 346, 2019; PENGoLINS)::

    E_d = ½ α ∫_Γ |d_a(s) − d_b(s)|² ds

and where the energy bends, the jump of the slope across ``Γ`` too, with the outward
conormal derivative ``∂_n d = ∇d · n`` of each side (``n`` in the tangent plane,
perpendicular to ``Γ``, pointing out of the patch)::

    E_r = ½ β ∫_Γ (∂_{n_a} d_a + ∂_{n_b} d_b)² ds

A smooth continuation across ``Γ`` has ``n_b = −n_a`` and the same gradient on both sides,
so it costs nothing; a hinge (a kink of ``d``) does. Each coordinate of the displacement is
coupled alike (the plate's energy is scalar per coordinate), so the matrices act on the
concatenated control points of the patches, ``(N, N)`` with ``N = Σ n_u n_v``.

Lengths ``ds`` and conormals come from the rest geometry. ``b``'s edge parameter is mapped
affinely onto ``a``'s (mirrored when the interface is reversed); the quadrature runs over
the union of both edges' knot spans, with :data:`EXTRA_POINTS` more Gauss points than the
products of the two edges' polynomials need (the measure ``|x_s|`` is constant on a straight
edge parametrised uniformly, and smooth otherwise).

The factors come from the material and the mesh (:func:`penalty_factors`), as in
PENGoLINS: ``α = C (A / h)``, ``β = C (D / h)`` with the membrane stiffness ``A``, the bending
stiffness ``D``, the element size ``h`` along ``Γ`` and ``C =`` :data:`PENALTY`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..body.interface import Interface
from ..errors import InputError
from ..knots import one_sided
from ..material import Material
from ..surface import Surface
from .shell import ShellMaterial

Array = NDArray[np.float64]

PENALTY = 1e5
"""Dimensionless penalty coefficient ``C``. PENGoLINS' default ``10³`` leaves a penalty error
of ``2·10⁻⁴`` in a split membrane's centre deflection, twice the discretisation error of its
6-span patches; at ``10⁵`` it is ``10⁻⁵`` (the projected penalty does not lock as it grows)."""
EXTRA_POINTS = 2
"""Gauss points per span beyond the ``max(p_a, p_b) + 1`` that integrate the products exactly."""
GAP_TOLERANCE = 1e-6
"""Largest distance, relative to the patches' size, between the two edges at a quadrature point."""


@dataclass(frozen=True)
class Side:
    """One side of a coupling line: ``surface`` near the line ``fixed = value``.

    ``fixed`` is the parameter held (``"u"``: the line runs along v), ``outward`` the sign of
    the held parameter's direction pointing out of the side (``+1``: the side lies below
    ``value``). The basis across the line is evaluated from inside the side (its one-sided
    limit at a ``C^0`` knot).
    """

    surface: Surface
    fixed: str
    value: float
    outward: int

    @classmethod
    def of_edge(cls, surface: Surface, edge: str) -> Side:
        """The side of ``surface`` at its edge ``"u0" | "u1" | "v0" | "v1"``."""
        (_, lu), (_, lv) = surface.domain
        fixed, end = edge[0], edge[1]
        length = lu if fixed == "u" else lv
        return cls(surface, fixed, 0.0 if end == "0" else length, -1 if end == "0" else 1)

    @property
    def running(self):
        """The basis along the line."""
        return self.surface.basis_v if self.fixed == "u" else self.surface.basis_u

    @property
    def breaks(self) -> Array:
        """Knot span ends of the running basis."""
        basis = self.running
        breaks = getattr(basis, "breaks", None)
        return np.arange(basis.cells + 1) * basis.h if breaks is None else np.asarray(breaks)

    def traces(self, s: Array) -> tuple[sp.csr_matrix, sp.csr_matrix, Array, Array]:
        """Operators on the net at running parameters ``s`` (shape ``(Q,)``).

        Returns ``V`` (values ``d``), ``Dn`` (outward conormal derivatives ``∂_n d``), both
        ``(Q, n_u n_v)``, the rest points ``x`` ``(Q, 3)`` and the line's speed ``|x_s|``.
        With ``f`` the held and ``r`` the running parameter, the conormal is
        ``n ∝ x_f − (x_f·x_r / x_r·x_r) x_r``, so ``∂_n d = ±(d_f − c d_r) / |x_f − c x_r|``.
        """
        surface = self.surface
        across = surface.basis_u if self.fixed == "u" else surface.basis_v
        i_f, b_f = one_sided(across, self.value, -self.outward, 1)      # (2, n_f + 1)
        i_r, b_r = self.running.nonzero_derivatives(s, 1)               # (2, Q, n_r + 1)
        n_v = surface.basis_v.size
        if self.fixed == "u":
            cols = i_f[None, :, None] * n_v + i_r[:, None, :]
        else:
            cols = i_r[:, :, None] * n_v + i_f[None, None, :]

        def operator(j_f: int, j_r: int) -> sp.csr_matrix:
            if self.fixed == "u":
                values = b_f[j_f][None, :, None] * b_r[j_r][:, None, :]
            else:
                values = b_r[j_r][:, :, None] * b_f[j_f][None, None, :]
            rows = np.broadcast_to(np.arange(s.size)[:, None, None], values.shape)
            return sp.csr_matrix((values.ravel(), (rows.ravel(), cols.ravel())),
                                 shape=(s.size, surface.shape[0] * n_v))

        V, Df, Dr = operator(0, 0), operator(1, 0), operator(0, 1)
        P = surface.control_points.reshape(-1, 3)
        x, x_f, x_r = V @ P, Df @ P, Dr @ P
        c = np.einsum("qi,qi->q", x_f, x_r) / np.einsum("qi,qi->q", x_r, x_r)
        length = np.linalg.norm(x_f - c[:, None] * x_r, axis=1)
        Dn = sp.diags(self.outward / length) @ (Df - sp.diags(c) @ Dr)
        return V, Dn.tocsr(), x, np.linalg.norm(x_r, axis=1)

    def element_size(self) -> float:
        """Mean length of the line's knot spans on the rest surface, ``h = |Γ| / spans``."""
        breaks = self.breaks
        s, w = _gauss(breaks, self.running.degree + 1 + EXTRA_POINTS)
        return float(w @ self.traces(s)[3]) / (breaks.size - 1)


def _gauss(breaks: Array, points: int) -> tuple[Array, Array]:
    """Gauss–Legendre points and weights, ``points`` on every span between ``breaks``."""
    ref_x, ref_w = np.polynomial.legendre.leggauss(points)
    left, width = breaks[:-1, None], np.diff(breaks)[:, None]
    return (left + 0.5 * width * (ref_x + 1.0)).ravel(), (0.5 * width * ref_w).ravel()


def _union(first: Array, second: Array, tol: float = 1e-12) -> Array:
    """Sorted union of two break sets on ``[0, 1]``, breaks closer than ``tol`` merged."""
    joined = np.sort(np.concatenate([first, second]))
    return joined[np.concatenate([[True], np.diff(joined) > tol])]


def _sides(patches: Sequence[Surface], interface: Interface) -> tuple[Side, Side]:
    for index in (interface.a, interface.b):
        if not 0 <= index < len(patches):
            raise InputError(f"interface {interface} names patch {index}, but the body has "
                             f"{len(patches)} patch(es)")
    return (Side.of_edge(patches[interface.a], interface.edge_a),
            Side.of_edge(patches[interface.b], interface.edge_b))


@dataclass(frozen=True)
class Line:
    """Both sides' traces at common quadrature points of ``Γ`` and the weights ``ds``.

    ``values`` and ``slopes`` hold, per side, the operators ``V`` and ``Dn`` of
    :meth:`Side.traces` (columns of that side's own net); ``projector`` is the coarser side's
    running basis at the points, ``(Q, n_r)``, the space a jump is measured in.
    """

    values: tuple[sp.csr_matrix, sp.csr_matrix]
    slopes: tuple[sp.csr_matrix, sp.csr_matrix]
    weights: Array
    projector: sp.csr_matrix


def _line(side_a: Side, side_b: Side, reversed_: bool, where: str) -> Line:
    """The traces of both sides on ``Γ``.

    On ``σ ∈ [0, 1]``: ``s_a = L_a σ`` and ``s_b = L_b σ`` (``L_b (1 − σ)`` if reversed),
    ``ds = |x_{a,s}| L_a dσ``, Gauss points on the union of both edges' spans. Raises where
    the two rest edges do not coincide.
    """
    lo_a, hi_a = side_a.breaks[[0, -1]]
    lo_b, hi_b = side_b.breaks[[0, -1]]
    unit_a = (side_a.breaks - lo_a) / (hi_a - lo_a)
    unit_b = (side_b.breaks - lo_b) / (hi_b - lo_b)
    breaks = _union(unit_a, 1.0 - unit_b if reversed_ else unit_b)
    degree = max(side_a.running.degree, side_b.running.degree)
    sigma, w = _gauss(breaks, degree + 1 + EXTRA_POINTS)
    s_a = lo_a + (hi_a - lo_a) * sigma
    s_b = lo_b + (hi_b - lo_b) * ((1.0 - sigma) if reversed_ else sigma)
    V_a, Dn_a, x_a, speed = side_a.traces(s_a)
    V_b, Dn_b, x_b, _ = side_b.traces(s_b)
    points = np.concatenate([side_a.surface.control_points.reshape(-1, 3),
                             side_b.surface.control_points.reshape(-1, 3)])
    size = float(np.ptp(points, axis=0).max())
    gap = np.linalg.norm(x_a - x_b, axis=1)
    if gap.max() > GAP_TOLERANCE * size:
        worst = int(gap.argmax())
        raise InputError(
            f"{where}: the two edges do not meet; at s = {s_a[worst]:.6g} of the first they are "
            f"{gap[worst]:.3g} apart ({gap[worst] / size:.2g} of the patches' size, more than "
            f"{GAP_TOLERANCE:g}). Check the edges and whether one is reversed")
    coarse_b = side_b.running.size <= side_a.running.size
    projector = (side_b.running.matrix(s_b) if coarse_b else side_a.running.matrix(s_a))
    return Line((V_a, V_b), (Dn_a, Dn_b), w * speed * (hi_a - lo_a), projector.tocsr())


def _merged(basis: sp.csr_matrix, count: int) -> sp.csr_matrix:
    """The trace space with its first and last ``count`` functions added to their neighbours.

    ``basis`` holds the functions at the quadrature points, ``(Q, n)``; the result has
    ``n − 2 count`` columns and still sums to one (a crosspoint modification).
    """
    n = basis.shape[1]
    if count < 0 or n <= 2 * count:
        raise InputError(f"cannot merge {count} end functions of a trace space of {n}")
    if count == 0:
        return basis
    target = np.arange(n)
    target[:count] = count
    target[n - count:] = n - count - 1
    keep = np.unique(target)
    S = sp.csr_matrix((np.ones(n), (np.arange(n), np.searchsorted(keep, target))),
                      shape=(n, keep.size))
    return (basis @ S).tocsr()


def _penalty(jump: sp.csr_matrix, weights: Array, factor: float,
             projector: sp.csr_matrix | None = None) -> sp.csr_matrix:
    """The matrix of ``½ factor ∫ (Π J d)² ds``.

    Without ``projector``, ``Π`` is the identity: ``factor Jᵀ W J`` (``W = diag(weights)``).
    With the basis ``Φ`` of a trace space at the points, ``Π`` is the ``L²(Γ)`` projection
    onto it: ``factor Gᵀ M_Φ⁻¹ G`` with ``G = Φᵀ W J`` and ``M_Φ = Φᵀ W Φ``, assembled on the
    few columns ``J`` touches.
    """
    if not np.isfinite(factor) or factor < 0:
        raise InputError(f"a penalty factor is finite and >= 0, got {factor!r}")
    if projector is None:
        K = (jump.T @ sp.diags(factor * weights) @ jump).tocsr()
        return ((K + K.T) * 0.5).tocsr()
    columns = np.unique(jump.tocoo().col)
    weighted = projector.T @ sp.diags(weights)
    G = np.asarray((weighted @ jump[:, columns]).todense())
    gram = np.asarray((weighted @ projector).todense())
    local = factor * G.T @ np.linalg.solve(gram, G)
    local = 0.5 * (local + local.T)
    rows = np.repeat(columns, columns.size)
    return sp.csr_matrix((local.ravel(), (rows, np.tile(columns, columns.size))),
                         shape=(jump.shape[1], jump.shape[1]))


def _place(operator: sp.csr_matrix, offset: int, size: int) -> sp.csr_matrix:
    """``operator``'s columns moved to ``offset …`` of ``size`` global columns."""
    coo = operator.tocoo()
    return sp.csr_matrix((coo.data, (coo.row, coo.col + offset)), shape=(operator.shape[0], size))


def _global(patches: Sequence[Surface], interface: Interface, offsets: Sequence[int]
            ) -> tuple[int, int, int]:
    if len(offsets) != len(patches):
        raise InputError(f"offsets has {len(offsets)} entries for {len(patches)} patches")
    size = int(offsets[-1]) + patches[-1].shape[0] * patches[-1].shape[1]
    return int(offsets[interface.a]), int(offsets[interface.b]), size


def displacement_penalty(patches: Sequence[Surface], interface: Interface, alpha: float,
                         offsets: Sequence[int], projected: bool = True, crosspoints: int = 0
                         ) -> sp.csr_matrix:
    """Matrix of ``½ α ∫_Γ |Π (d_a − d_b)|² ds`` over the concatenated control points.

    ``Π`` is the ``L²(Γ)`` projection onto the splines along the coarser edge (the one with
    fewer functions; ``b`` on a tie): a penalised mortar condition. Without it
    (``projected=False``, ``Π = I``) a strong penalty asks the traces of two unrelated spline
    spaces to agree everywhere and locks: on a square split into 8 and 6 spans along the
    interface the centre deflection moves by 10× its discretisation error between
    ``C = 10³`` and ``10⁴`` (tests/test_coupling.py). Where both edges carry the same
    splines ``Π`` changes nothing.

    Parameters
    ----------
    patches : sequence of Surface
        The body's patches (rest shapes).
    interface : Interface
    alpha : float
        Penalty factor (:func:`penalty_factors`).
    offsets : sequence of int
        Index of each patch's first control point in the concatenation (flattened row-major
        per patch, as :attr:`Surface.control_points`).
    projected : bool
    crosspoints : int
        Functions at each end of the coarser edge's space added to their neighbour before
        projecting (the crosspoint modification of mortar methods). An end held by its
        boundary ties ``Π d`` there a second time; for bending (a clamped end fixes the
        first two coefficients, the slope's among them) one is merged, else the plate locks:
        with none its centre deflection moves by 0.5 % from ``C = 10⁴`` to ``10⁶``, with one
        by 0.005 %. A membrane needs none (:func:`interface_penalty` chooses).

    Returns
    -------
    scipy.sparse.csr_matrix, shape ``(N, N)``
        Symmetric positive semi-definite, to be added to the block-diagonal stiffness; acts
        on each coordinate alike.
    """
    side_a, side_b = _sides(patches, interface)
    line = _line(side_a, side_b, interface.reversed, f"interface {interface}")
    off_a, off_b, size = _global(patches, interface, offsets)
    jump = _place(line.values[0], off_a, size) - _place(line.values[1], off_b, size)
    space = _merged(line.projector, crosspoints) if projected else None
    return _penalty(jump, line.weights, alpha, space)


def rotation_penalty(patches: Sequence[Surface], interface: Interface, beta: float,
                     offsets: Sequence[int], projected: bool = True) -> sp.csr_matrix:
    """Matrix of ``½ β ∫_Γ (Π (∂_{n_a} d_a + ∂_{n_b} d_b))² ds`` (outward conormals).

    Same arguments, layout and projection as :func:`displacement_penalty`, with ``beta``.
    """
    side_a, side_b = _sides(patches, interface)
    line = _line(side_a, side_b, interface.reversed, f"interface {interface}")
    off_a, off_b, size = _global(patches, interface, offsets)
    jump = _place(line.slopes[0], off_a, size) + _place(line.slopes[1], off_b, size)
    return _penalty(jump, line.weights, beta, line.projector if projected else None)


def interface_penalty(patches: Sequence[Surface], interface: Interface,
                      material: Material | ShellMaterial, offsets: Sequence[int]
                      ) -> sp.csr_matrix:
    """The coupling of a non-conforming interface, every factor from the material and the mesh.

    :func:`displacement_penalty` with ``α`` of :func:`penalty_factors` at the element size
    :func:`interface_size`, plus, where the energy bends, :func:`rotation_penalty` with ``β``
    (and one crosspoint function merged at each end of the displacement's space).
    """
    alpha, beta = penalty_factors(material, interface_size(patches, interface))
    bending = beta > 0
    K = displacement_penalty(patches, interface, alpha, offsets, crosspoints=int(bending))
    return K + rotation_penalty(patches, interface, beta, offsets) if bending else K


def c0_lines(surface: Surface) -> list[tuple[str, float]]:
    """The ``C^0`` knot lines inside a face: ``(direction, knot)``, ``"u"`` for ``u = knot``.

    A knot repeated as often as the degree leaves the surface (and its displacement) only
    continuous there: an interface between the two sides, whose displacement is continuous
    already and whose rotation :func:`c0_rotation_penalty` couples.
    """
    return [(direction, float(knot))
            for direction, basis in (("u", surface.basis_u), ("v", surface.basis_v))
            for knot in getattr(basis, "c0_knots", ())]


def c0_sides(surface: Surface, direction: str, knot: float) -> tuple[Side, Side]:
    """The sides below (outward ``+1``) and above (``−1``) the line ``direction = knot``."""
    if direction not in ("u", "v"):
        raise InputError(f"a C0 line's direction is 'u' or 'v', got {direction!r}")
    if (direction, float(knot)) not in c0_lines(surface):
        lines = ", ".join(f"{d} = {x:.12g}" for d, x in c0_lines(surface)) or "none"
        raise InputError(f"{direction} = {knot:.12g} is not a C0 knot line of {surface.name!r} "
                         f"(its C0 lines: {lines})")
    return Side(surface, direction, float(knot), 1), Side(surface, direction, float(knot), -1)


def c0_rotation_penalty(surface: Surface, direction: str, knot: float, beta: float,
                        offset: int = 0, size: int | None = None) -> sp.csr_matrix:
    """Matrix of ``½ β ∫ (∂_{n_-} d_- + ∂_{n_+} d_+)² ds`` along the C0 line ``direction = knot``.

    ``d_-`` and ``d_+`` are the one-sided limits from the spans below and above the knot
    (:func:`splinedeform.knots.one_sided`), with their outward conormals; the quadrature runs
    over the spans along the line. The surface's control points are ``offset …`` of ``size``
    global ones (default: the surface alone).
    """
    below, above = c0_sides(surface, direction, knot)
    s, w = _gauss(below.breaks, below.running.degree + 1 + EXTRA_POINTS)
    _, D_below, _, speed = below.traces(s)
    _, D_above, _, _ = above.traces(s)
    count = surface.shape[0] * surface.shape[1]
    size = offset + count if size is None else int(size)
    return _penalty(_place(D_below + D_above, offset, size), w * speed, beta)


def interface_size(patches: Sequence[Surface], interface: Interface) -> float:
    """Element size ``h`` along an interface: the smaller of its two edges' mean span lengths."""
    return min(side.element_size() for side in _sides(patches, interface))


def c0_size(surface: Surface, direction: str, knot: float) -> float:
    """Element size ``h`` along a C0 line: its mean span length on the rest surface."""
    return c0_sides(surface, direction, knot)[0].element_size()


def penalty_factors(material: Material | ShellMaterial, h: float) -> tuple[float, float]:
    """Displacement and rotation factors ``(α, β)`` from the material and the element size ``h``.

    Plate under tension (:class:`~splinedeform.material.Material`): with the tension
    ``T = max(w10, w01)`` and the bending weight ``D = max(w20, w11, w02)``,
    ``α = C (T / h + D / h³)`` (a plate without tension still needs its displacement tied, at
    the bending energy's scale of a jump) and ``β = C D / h``.

    Kirchhoff–Love shell (:class:`~splinedeform.physics.shell.ShellMaterial`), as PENGoLINS:
    ``α = C E t / ((1 − ν²) h)``, ``β = C E t³ / (12 (1 − ν²) h)``.
    ``C`` is :data:`PENALTY`.
    """
    if not np.isfinite(h) or h <= 0:
        raise InputError(f"the element size along an interface must be finite and > 0, got {h!r}")
    if isinstance(material, ShellMaterial):
        membrane = material.E * material.thickness / (1.0 - material.nu ** 2)
        bending = membrane * material.thickness ** 2 / 12.0
        return PENALTY * membrane / h, PENALTY * bending / h
    tension = max(material.w10, material.w01)
    bending = max(material.w20, material.w11, material.w02)
    return PENALTY * (tension / h + bending / h ** 3), PENALTY * bending / h
