"""The rotation of a curved shell's clamped edges, held by Nitsche's terms.

Clamping holds ``d = 0`` on the edge (hence ``∂_s d = 0`` along it) and the rotation of
the normal about the edge, ``a_3·∂_n d = 0``; the in-plane slope across the edge is free:
``a_n·∂_n d`` and ``a_s·∂_n d`` are the membrane strains ``ε_nn`` and ``2ε_ns`` there,
which the exact solution of a curved shell does not make zero. Holding the whole slope
``∂_n d = 0`` (the second row of control points at rest, :mod:`.shell_edges`) would hold
them too: an over-constraint that converges only slowly on a curved shell. On a flat
one whose normal is a coordinate axis ``e_a`` the rotation is the slope of ``d_a`` alone:
``d = 0`` and ``∂_n d_a = 0`` are held exactly in ``T`` (the plate's clamping), and the
in-plane slopes stay free, as the membrane under in-plane loads needs (:func:`normal_axis`).
A flat surface in a tilted plane takes Nitsche's terms, as a curved one does.

So on a curved surface a clamped edge is pinned in ``T`` (``d = 0``) and the rotation is
held by the clamped Nitsche terms of the trimmed shell
(:func:`splinedeform.trim.energy_forms.nitsche_matrix` with the shell's
:func:`~splinedeform.trim.shell_trimmed.shell_form`) on ``p + 2`` Gauss points per cell of
the edge. With ``d = v = 0`` on the edge the boundary form reduces to
``b(v, d) = ∮ (g(v)·n)(a_3·∂_n d) ds``, ``g ∥ a_3`` (the moment), and the penalty to
``γ_1 ∮ (a_3·∂_n d)(a_3·∂_n v) ds``, ``γ_1 = β w_b/h``: the terms of ``d`` itself vanish
in ``range T`` and are not assembled (nor the third derivatives and coefficient
derivatives they need).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..quadrature import gauss_points
from ..surface import Surface
from .shell import ShellMaterial
from .shell_rigid import RigidMotions

Array = NDArray[np.float64]
#: control points within this fraction of the net's extent from one plane are coplanar
FLAT = 1e-10


def normal_axis(surface: Surface) -> int | None:
    """``a`` where the surface lies in a plane ``x_a = const`` (its normal ``±e_a``, the
    net's spread along ``e_a`` within :data:`FLAT` of its extent); ``None`` otherwise."""
    P = surface.control_points.reshape(-1, 3)
    spread = np.ptp(P, axis=0)
    flat = np.flatnonzero(spread <= FLAT * max(float(spread.max()), 1e-300))
    return int(flat[0]) if flat.size == 1 else None


def weak_clamps(surface: Surface, edges: Mapping[str, str]) -> tuple[str, ...]:
    """The clamped edges whose rotation Nitsche's terms hold: all of a surface's that does
    not lie in a coordinate plane (:func:`normal_axis`)."""
    clamped = tuple(e for e, kind in edges.items() if kind == "clamped")
    return clamped if clamped and normal_axis(surface) is None else ()


def edge_quadrature(surface: Surface, edge: str) -> tuple[Array, Array, Array, Array, Array]:
    """Gauss points ``p (P, 2)`` of an edge, their parameter arc weights ``ds``, outward
    parameter normals ``n``, tangents ``s`` and knot-cell sizes ``h`` (the smaller side of
    the edge's cell)."""
    along = surface.basis_v if edge[0] == "u" else surface.basis_u
    across = surface.basis_u if edge[0] == "u" else surface.basis_v
    q = max(surface.basis_u.degree, surface.basis_v.degree) + 2
    x, w = gauss_points(along, q)
    cells_along = np.repeat(w.reshape(-1, q).sum(axis=1), q)
    cells_across = gauss_points(across, q)[1].reshape(-1, q).sum(axis=1)
    end = edge[1] == "1"
    h = np.minimum(cells_along, cells_across[-1 if end else 0])
    fixed = np.full_like(x, across.length if end else 0.0)
    sign = 1.0 if end else -1.0
    if edge[0] == "u":
        p, n, s = np.stack([fixed, x], 1), [sign, 0.0], [0.0, sign]
    else:
        p, n, s = np.stack([x, fixed], 1), [0.0, sign], [-sign, 0.0]
    return (p, w, np.broadcast_to(n, p.shape).copy(), np.broadcast_to(s, p.shape).copy(), h)


def clamp_rotation(surface: Surface, material: ShellMaterial, edges: Mapping[str, str],
                   displacement_held: bool = True) -> sp.csr_matrix | None:
    """Nitsche's terms holding the rotation of the :func:`weak_clamps` edges, ``(3N, 3N)``
    interleaved; ``None`` where there are none. ``T`` holds ``d = 0`` on these edges, so
    by default the terms of ``d`` itself, which vanish in ``range T``, are left out
    (``displacement_held`` of :func:`~splinedeform.trim.energy_forms.nitsche_matrix`);
    ``False`` assembles them too."""
    weak = weak_clamps(surface, edges)
    if not weak:
        return None
    from ..trim.energy_forms import nitsche_matrix
    from ..trim.model_matrices import nitsche_penalty
    from ..trim.shell_trimmed import shell_form

    parts = [edge_quadrature(surface, e) for e in weak]
    p, ds, n, s, h = (np.concatenate(k) for k in zip(*parts))
    degree = max(surface.basis_u.degree, surface.basis_v.degree)
    return nitsche_matrix(surface, shell_form(material), p, ds, n, s,
                          np.ones(len(p), bool), h, nitsche_penalty(degree), displacement_held)


def held(T: sp.spmatrix) -> RigidMotions:
    """No free rigid motion: one in ``range T`` is at rest on a clamped edge, so at most a
    rotation about that edge's line, whose rotation ``a_3·∂_n d`` the penalty holds."""
    return RigidMotions(np.zeros((T.shape[1], 0)), np.zeros((6, 0)))
