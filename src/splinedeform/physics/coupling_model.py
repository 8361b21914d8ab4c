"""The couplings a model adds to its patches' stiffness: interfaces and C0 knot lines.

A model's stiffness over the concatenated control points is the patches' own matrices on
the diagonal plus the penalties of :mod:`.coupling`, every factor from the material and the
mesh (:func:`~.coupling.penalty_factors`)::

    K = diag(K_1, …, K_P) + Σ_{non-conforming Γ} (K_α + K_β) + Σ_{conforming Γ} K_β
        + Σ_{C0 lines} K_β

* a conforming interface has its control points merged by the constraint map, so its
  displacement is continuous exactly; where the energy bends, the rotation penalty ``K_β``
  ties the slopes across it;
* a non-conforming interface (different knots or degrees) gets the displacement penalty
  ``K_α`` projected onto the finer edge's splines (a penalised mortar condition) and, where
  the energy bends, ``K_β``: :func:`~.coupling.interface_penalty`;
* a ``C^0`` knot line inside a patch is the interface between its two sides, whose
  displacement is continuous already: ``K_β`` only (:func:`~.coupling.c0_rotation_penalty`);
* smooth conforming interfaces and C0 lines (of a plate or a shell, one patch or a body)
  have their tangent continuity tied exactly by the constraint map (:mod:`.coupling_ties`),
  and no ``K_β``.

Each penalty's ends take the boundary condition of the edges they lie on (the crosspoints
those hold, :data:`~.coupling.HELD`): an end on a clamped edge has its first two trace
functions merged, a pinned one its first, a free one (or an end on another interface) none.
A shell's edge kinds count as the preset that holds as much of the trace: ``diaphragm`` as
``pinned``, the others as ``free``. Mass is unchanged: the penalties are stiffness only.
"""

from __future__ import annotations

from typing import Collection, Mapping, Sequence

import scipy.sparse as sp

from ..body.interface import Interface
from ..material import Material
from ..surface import Surface
from . import coupling
from .shell import ShellMaterial

AS_HELD = {"clamped": "clamped", "pinned": "pinned", "diaphragm": "pinned"}
"""An edge condition as the preset of :data:`~.coupling.HELD` it holds an end with."""

ALONG = {"u0": ("v0", "v1"), "u1": ("v0", "v1"), "v0": ("u0", "u1"), "v1": ("u0", "u1")}
"""The edges at the start and the end of each edge (in its increasing parameter)."""


def held(*conditions: str | None) -> str:
    """The strongest of the conditions at one end (``None``: no boundary edge there)."""
    presets = [AS_HELD.get(c or "free", "free") for c in conditions]
    return max(presets, key=lambda p: coupling.HELD[p])


def bends(material: Material | ShellMaterial) -> bool:
    """Whether the energy has bending, so that rotations across a kink must be coupled."""
    return isinstance(material, ShellMaterial) or bool(
        max(material.w20, material.w11, material.w02))


def c0_coupling(surface: Surface, material: Material | ShellMaterial,
                edges: Mapping[str, str], offset: int = 0, size: int | None = None,
                exact: Collection[tuple[str, float]] = ()) -> sp.csr_matrix | None:
    """Sum of the rotation penalties across ``surface``'s C0 lines, or ``None`` if none.

    A line ``u = knot`` runs along ``v`` from edge ``v0`` to ``v1`` (a line ``v = knot``
    from ``u0`` to ``u1``); ``edges`` are the patch's edge conditions. The layout is
    :func:`~.coupling.c0_rotation_penalty`'s (scalar control points ``offset …`` of ``size``)
    for a plate, the interleaved one of :func:`~.coupling.shell_c0_rotation_penalty` for a
    shell. ``None`` also where the energy does not bend. The lines in ``exact``
    (``(direction, knot)``, tied by the constraint map: :mod:`.coupling_ties`) are
    left out.
    """
    lines = [line for line in coupling.c0_lines(surface) if line not in exact]
    if not lines or not bends(material):
        return None
    shell = isinstance(material, ShellMaterial)
    penalty = coupling.shell_c0_rotation_penalty if shell else coupling.c0_rotation_penalty
    total = None
    for direction, knot in lines:
        start, end = ALONG["u0" if direction == "u" else "v0"]
        ends = (coupling.HELD[held(edges.get(start))], coupling.HELD[held(edges.get(end))])
        beta = coupling.penalty_factors(material, coupling.c0_size(surface, direction, knot))[1]
        K = penalty(surface, direction, knot, beta, offset, size, ends)
        total = K if total is None else total + K
    return total


def interface_ends(interface: Interface, presets: Mapping[tuple[int, str], str]
                   ) -> tuple[str, str]:
    """Conditions holding an interface's start and end (in ``a``'s parameter): at each end
    the stronger of the two patches' edges there (``presets`` keyed ``(patch, edge)``)."""
    a_ends = ALONG[interface.edge_a]
    b_ends = ALONG[interface.edge_b][::-1] if interface.reversed else ALONG[interface.edge_b]
    return tuple(held(presets.get((interface.a, ea)), presets.get((interface.b, eb)))
                 for ea, eb in zip(a_ends, b_ends))  # type: ignore[return-value]


def interface_coupling(patches: Sequence[Surface], interfaces: Sequence[Interface],
                       material: Material | ShellMaterial,
                       presets: Mapping[tuple[int, str], str], offsets: Sequence[int],
                       exact: Collection[int] = ()) -> sp.csr_matrix | None:
    """Sum of the interfaces' penalties (module docstring), or ``None`` if there are none.

    Non-conforming interfaces: :func:`~.coupling.interface_penalty`; conforming ones (merged
    by the constraint map) the rotation penalty alone, where the energy bends, unless their
    index is in ``exact`` (their tangent continuity tied by the constraint map too:
    :mod:`.coupling_ties`). ``offsets`` are the patches' first control points in
    the concatenation.
    """
    total = None
    shell = isinstance(material, ShellMaterial)
    for number, interface in enumerate(interfaces):
        if interface.conforming and number in exact:
            continue
        ends = interface_ends(interface, presets)
        if not interface.conforming:
            K = coupling.interface_penalty(patches, interface, material, offsets, ends)
        elif bends(material):
            beta = coupling.penalty_factors(material,
                                            coupling.interface_size(patches, interface))[1]
            rotation = coupling.shell_rotation_penalty if shell else coupling.rotation_penalty
            K = rotation(patches, interface, beta, offsets,
                         crosspoints=tuple(coupling.HELD[e] for e in ends))
        else:
            continue
        total = K if total is None else total + K
    return total
