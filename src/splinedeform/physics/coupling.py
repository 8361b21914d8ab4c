"""Weak coupling of patches across an interface: displacement and rotation penalties.

Two patches ``a`` and ``b`` meet along a curve ``Γ`` (an :class:`~splinedeform.body.Interface`,
or a ``C^0`` knot line inside one patch, whose two sides meet there). Where their control
points cannot be merged (different knots or degrees along ``Γ``) the displacement jump is
penalised (Herrema et al., CMAME 346, 2019; PENGoLINS)::

    E_d = ½ α ∫_Γ |Π (d_a(s) − d_b(s))|² ds

and where the energy bends, the jump of the slope across ``Γ`` too, with the outward
conormal derivative ``∂_n d = ∇d · n`` of each side (``n`` in the tangent plane,
perpendicular to ``Γ``, pointing out of the patch)::

    E_r = ½ β ∫_Γ (Π (∂_{n_a} d_a + ∂_{n_b} d_b))² ds

``Π`` is the ``L²(Γ)`` projection onto the splines of the finer edge (a penalised mortar
condition, :func:`displacement_penalty`): the plain penalty (``Π = I``) locks on edges whose
knots differ. A smooth continuation across ``Γ`` has ``n_b = −n_a`` and the same gradient on
both sides, so it costs nothing; a hinge (a kink of ``d``) does. Each coordinate of the
displacement is coupled alike (the plate's energy is scalar per coordinate), so the matrices
act on the concatenated control points of the patches, ``(N, N)`` with ``N = Σ n_u n_v``; the
shell's forms (``shell_*``) act on its interleaved unknowns, and its rotation is that of each
side's conormal fibre about the common tangent, which keeps a crease's angle.

Lengths ``ds`` and conormals come from the rest geometry. ``b``'s edge parameter is mapped
affinely onto ``a``'s (mirrored when the interface is reversed); the quadrature runs over
the union of both edges' knot spans, with
:data:`~splinedeform.physics.coupling_traces.EXTRA_POINTS` more Gauss points than the products
of the two edges' polynomials need (the measure ``|x_s|`` is constant on a straight edge
parametrised uniformly, and smooth otherwise), or a rational basis' own number.

The factors come from the material and the mesh (:func:`penalty_factors`), as in
PENGoLINS: ``α = C (A / h)``, ``β = C (D / h)`` with the membrane stiffness ``A``, the bending
stiffness ``D``, the element size ``h`` along ``Γ`` and ``C =`` :data:`PENALTY`;
:func:`interface_penalty` assembles both for an interface.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..body.interface import Interface
from ..errors import InputError
from ..material import Material
from ..surface import Surface
from .coupling_traces import Line, Side, common_line
from .shell import ShellMaterial

Array = NDArray[np.float64]

PENALTY = 1e5
"""Dimensionless penalty coefficient ``C``. PENGoLINS' default ``10³`` leaves a penalty error
of ``1.2·10⁻⁴`` in the split membrane's centre deflection (tests/test_coupling_plates.py),
three times the discretisation error of its 8-span side; at ``10⁵`` it is ``1.1·10⁻⁵``. The
projected penalty does not lock as it grows, and what is left of its error falls as ``1/C``;
the price is the conditioning, ``C`` times that of the patches' own stiffness."""


def _sides(patches: Sequence[Surface], interface: Interface) -> tuple[Side, Side]:
    for index in (interface.a, interface.b):
        if not 0 <= index < len(patches):
            raise InputError(f"interface {interface} names patch {index}, but the body has "
                             f"{len(patches)} patch(es)")
    return (Side.of_edge(patches[interface.a], interface.edge_a),
            Side.of_edge(patches[interface.b], interface.edge_b))


def _name(interface: Interface) -> str:
    return (f"the interface of patch {interface.a} edge {interface.edge_a} and patch "
            f"{interface.b} edge {interface.edge_b}"
            + (" (reversed)" if interface.reversed else ""))


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
                         offsets: Sequence[int], projected: bool = True,
                         crosspoints: int | tuple[int, int] = 0
                         ) -> sp.csr_matrix:
    """Matrix of ``½ α ∫_Γ |Π (d_a − d_b)|² ds`` over the concatenated control points.

    ``Π`` is the ``L²(Γ)`` projection onto the splines along the finer edge (the one with
    more functions; ``a`` on a tie), less the ``crosspoints`` at its ends: a penalised
    mortar condition with the finer side as the slave. As ``α`` grows the answer tends to
    the mortar solution instead of locking. Without it (``projected=False``, ``Π = I``) a
    strong penalty asks the traces of two unrelated spline spaces to agree everywhere and
    locks (tests/test_coupling_plates.py). Where both edges carry the same splines ``Π``
    changes nothing but the merged ends.

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
    crosspoints : int or (int, int)
        Functions at the start and the end of the interface (in ``a``'s parameter) added to
        their neighbour before projecting: the coefficients the boundary holds there
        (:data:`HELD`: 0 free, 1 pinned, 2 clamped). A held end would be tied a second
        time by the projection, and the plate locks: a clamped square split into 12 and 8
        spans moves by 0.5 % of its centre deflection with none merged, 0.01 % with two.

    Returns
    -------
    scipy.sparse.csr_matrix, shape ``(N, N)``
        Symmetric positive semi-definite, to be added to the block-diagonal stiffness; acts
        on each coordinate alike.
    """
    side_a, side_b = _sides(patches, interface)
    line = common_line(side_a, side_b, interface.reversed, _name(interface))
    off_a, off_b, size = _global(patches, interface, offsets)
    return line_penalty(line, "values", (off_a, off_b, size), alpha,
                        line.space(crosspoints) if projected else None)


def line_penalty(line: Line, kind: str, layout: tuple[int, int, int], factor: float,
                 space: sp.csr_matrix | None) -> sp.csr_matrix:
    """The penalty of one jump on a coupling line, whatever the line's shape.

    ``kind = "values"``: ``½ factor ∫ (Π (d_a − d_b))² ds``; ``kind = "slopes"``:
    ``½ factor ∫ (Π (∂_{n_a} d_a + ∂_{n_b} d_b))² ds`` (outward conormals, so a smooth
    continuation costs nothing). ``layout`` is ``(offset_a, offset_b, size)``: the sides'
    first control points among ``size`` concatenated ones; ``space`` the basis ``Φ`` of the
    trace space at the line's points (``None``: ``Π = I``). An iso-edge's line
    (:func:`~.coupling_traces.common_line`) and a trim curve's
    (:func:`~.coupling_curves.curve_line`) are penalised alike.
    """
    off_a, off_b, size = layout
    sign = {"values": -1.0, "slopes": 1.0}[kind]
    a, b = (getattr(trace, kind) for trace in line.sides)
    jump = _place(a, off_a, size) + sign * _place(b, off_b, size)
    return _penalty(jump.tocsr(), line.weights, factor, space)


def rotation_penalty(patches: Sequence[Surface], interface: Interface, beta: float,
                     offsets: Sequence[int], projected: bool = True,
                     crosspoints: int | tuple[int, int] = 0) -> sp.csr_matrix:
    """Matrix of ``½ β ∫_Γ (Π (∂_{n_a} d_a + ∂_{n_b} d_b))² ds`` (outward conormals).

    Same arguments, layout and projection as :func:`displacement_penalty`, with ``beta``.
    Each coordinate's slope is tied, which is the smooth continuation where the rest
    shape is ``G1`` (``n_b = −n_a``); across a crease the scalar energies have no rotation
    to keep, and :func:`shell_rotation_penalty` keeps the shell's angle.
    """
    side_a, side_b = _sides(patches, interface)
    line = common_line(side_a, side_b, interface.reversed, _name(interface))
    off_a, off_b, size = _global(patches, interface, offsets)
    return line_penalty(line, "slopes", (off_a, off_b, size), beta,
                        line.space(crosspoints) if projected else None)


def _interleaved(operator: sp.csr_matrix, direction: Array, offset: int, size: int
                 ) -> sp.csr_matrix:
    """``operator`` (on scalar control values) dotted with a vector ``direction[q]`` per row:
    columns ``3 (offset + k) + c`` of ``3 size`` interleaved unknowns (the shell's layout)."""
    coo = operator.tocoo()
    rows = np.repeat(coo.row, 3)
    cols = 3 * (np.repeat(coo.col, 3) + offset) + np.tile(np.arange(3), coo.nnz)
    values = (coo.data[:, None] * direction[coo.row]).ravel()
    return sp.csr_matrix((values, (rows, cols)), shape=(operator.shape[0], 3 * size))


def shell_displacement_penalty(patches: Sequence[Surface], interface: Interface, alpha: float,
                               offsets: Sequence[int], crosspoints: int | tuple[int, int] = 0
                               ) -> sp.csr_matrix:
    """:func:`displacement_penalty` on the shell's interleaved unknowns (dof ``3k + c``):
    ``½ α ∫ |Π (d_a − d_b)|² ds`` for the displacement vector, ``(3N, 3N)``."""
    scalar = displacement_penalty(patches, interface, alpha, offsets, crosspoints=crosspoints)
    return sp.kron(scalar, sp.identity(3), format="csr")


def shell_rotation_penalty(patches: Sequence[Surface], interface: Interface, beta: float,
                           offsets: Sequence[int], crosspoints: int | tuple[int, int] = 0
                           ) -> sp.csr_matrix:
    """Matrix of ``½ β ∫_Γ (Π (θ_a − θ_b))² ds`` on the shell's interleaved unknowns.

    ``θ = ∂_n d · (τ × n)`` is the linearised rotation of a side's conormal fibre ``n``
    about the common tangent ``τ`` (``a``'s). A rigid motion ``d = ω × x`` turns every fibre
    by ``ω·τ``, whatever the angle between the sides, so the angle between them is what is
    kept: ``G1`` where the rest shape is smooth, the crease where it is not (Kiendl et al.,
    CMAME 199, 2010; Herrema et al. 2019). On a flat body ``τ × n = ∓ e_z`` and this is
    :func:`rotation_penalty` of the deflection.
    """
    side_a, side_b = _sides(patches, interface)
    line = common_line(side_a, side_b, interface.reversed, _name(interface))
    off_a, off_b, size = _global(patches, interface, offsets)
    return _penalty(_rotation_jump(line, off_a, off_b, size), line.weights, beta,
                    line.space(crosspoints))


def _rotation_jump(line: Line, off_a: int, off_b: int, size: int) -> sp.csr_matrix:
    """``θ_a − θ_b`` at the line's points, ``(Q, 3 size)``."""
    a, b = line.sides
    tangent = a.tangent
    return (_interleaved(a.slopes, np.cross(tangent, a.conormal), off_a, size)
            - _interleaved(b.slopes, np.cross(tangent, b.conormal), off_b, size))


def shell_line_penalty(line: Line, layout: tuple[int, int, int], alpha: float, beta: float,
                       space: sp.csr_matrix | None) -> sp.csr_matrix:
    """``½ α ∫ |Π (d_a − d_b)|² ds + ½ β ∫ (Π (θ_a − θ_b))² ds`` on any coupling line (an
    iso-edge's, a trim curve's, a shared stretch's), on the shell's interleaved unknowns:
    :func:`shell_displacement_penalty` and :func:`shell_rotation_penalty` on ``line``,
    ``layout`` as :func:`line_penalty`'s (in control points)."""
    off_a, off_b, size = layout
    values = line_penalty(line, "values", layout, alpha, space)
    rotation = _penalty(_rotation_jump(line, off_a, off_b, size), line.weights, beta, space)
    return (sp.kron(values, sp.identity(3), format="csr") + rotation).tocsr()


def shell_c0_rotation_penalty(surface: Surface, direction: str, knot: float, beta: float,
                              offset: int = 0, size: int | None = None,
                              crosspoints: int | tuple[int, int] = 0
                              ) -> sp.csr_matrix:
    """:func:`shell_rotation_penalty` across a C0 line (:func:`c0_rotation_penalty`'s layout,
    interleaved): the crease of the rest shape there is kept."""
    line = _c0_line(surface, direction, knot)
    size = offset + surface.shape[0] * surface.shape[1] if size is None else int(size)
    return _penalty(_rotation_jump(line, offset, offset, size), line.weights, beta,
                    line.space(crosspoints))


HELD = {"free": 0, "pinned": 1, "clamped": 2}
"""Coefficients of an edge's trace an end condition fixes, the crosspoints merged there."""


def interface_penalty(patches: Sequence[Surface], interface: Interface,
                      material: Material | ShellMaterial, offsets: Sequence[int],
                      ends: tuple[str, str] = ("free", "free")) -> sp.csr_matrix:
    """The coupling of a non-conforming interface, every factor from the material and the mesh.

    :func:`displacement_penalty` with ``α`` of :func:`penalty_factors` at the element size
    :func:`interface_size`, plus, where the energy bends, :func:`rotation_penalty` with ``β``;
    for a shell their vector forms on its interleaved unknowns (``(3N, 3N)``).
    ``ends`` are the boundary conditions holding the interface's start and end (in ``a``'s
    parameter), ``"free" | "pinned" | "clamped"``: the crosspoints (:data:`HELD`).
    """
    for end in ends:
        if end not in HELD:
            raise InputError(f"an interface end is one of {tuple(HELD)}, got {end!r}")
    crosspoints = (HELD[ends[0]], HELD[ends[1]])
    alpha, beta = penalty_factors(material, interface_size(patches, interface))
    if isinstance(material, ShellMaterial):
        return (shell_displacement_penalty(patches, interface, alpha, offsets, crosspoints)
                + shell_rotation_penalty(patches, interface, beta, offsets, crosspoints))
    K = displacement_penalty(patches, interface, alpha, offsets, crosspoints=crosspoints)
    if beta == 0:
        return K
    return K + rotation_penalty(patches, interface, beta, offsets, crosspoints=crosspoints)


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
                        offset: int = 0, size: int | None = None,
                        crosspoints: int | tuple[int, int] = 0
                        ) -> sp.csr_matrix:
    """Matrix of ``½ β ∫ (∂_{n_-} d_- + ∂_{n_+} d_+)² ds`` along the C0 line ``direction = knot``.

    ``d_-`` and ``d_+`` are the one-sided limits from the spans below and above the knot
    (:func:`splinedeform.knots.one_sided`), with their outward conormals: the interface
    between the two sides, on the same splines along the line (so the projection changes
    nothing but the ``crosspoints``, at the line's start and end or one count for both).
    The surface's control points are ``offset …`` of ``size`` global ones (default: the
    surface alone).
    """
    line = _c0_line(surface, direction, knot)
    count = surface.shape[0] * surface.shape[1]
    size = offset + count if size is None else int(size)
    return line_penalty(line, "slopes", (offset, offset, size), beta, line.space(crosspoints))


def _c0_line(surface: Surface, direction: str, knot: float) -> Line:
    below, above = c0_sides(surface, direction, knot)
    return common_line(below, above, False, f"C0 line {direction} = {knot:.12g}")


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
