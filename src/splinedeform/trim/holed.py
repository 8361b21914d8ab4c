"""The parameter rectangle less holes: its quadrature, and the rectangle's edge conditions
composed with Höllig's extension.

When the outer trim loop is the rectangle itself
(:func:`~splinedeform.trim.surface_trim.whole_rectangle`) the region is
``R \\ ∪ H_k``, integrated as ``∫_{R∖H} f = Σ_C ∫_C f − Σ_k ∫_{C∩H_k} f``: tensor Gauss on
every cell not inside a hole, less each hole's cut-cell rule
(:func:`~splinedeform.trim.quadrature.trim_quadrature` of the hole alone). Its edges
``u0 … v1`` keep the conditions of :mod:`splinedeform.boundary`: with ``T_e`` their map
(identity on the kept coefficients ``K``) and ``E`` the extension (identity on the inner
coefficients ``I``), the map is ``T = T_e E[K, F]`` over the free set ``F = I ∩ K``,
with the holes' outer B-splines tied to arrays of kept coefficients only. Fixed control
points (on any trimmed region) are left out of ``K`` the same way.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..boundary import build_constraints
from ..errors import InputError
from .cells import CUT, INSIDE, OUTSIDE, Grid
from .loops import TrimDomain
from .quadrature import TrimQuadrature, cell_gauss, trim_quadrature
from .surface_trim import extension_knots, net_weights_of, surface_degrees
from .web import web_basis


def holed_quadrature(domain: TrimDomain, grid: Grid, order: int) -> TrimQuadrature:
    """Quadrature of the rectangle less the holes of ``domain`` (module docstring)."""
    classes = np.full(grid.cells, INSIDE)
    points, weights, cells = [], [], []
    for hole in domain.holes:
        q = trim_quadrature(TrimDomain(hole), grid, order)
        classes[q.classes == INSIDE] = OUTSIDE
        classes[q.classes == CUT] = CUT
        on_cut = q.classes[q.cell[:, 0], q.cell[:, 1]] == CUT
        points.append(q.points[on_cut])
        weights.append(-q.weights[on_cut])
        cells.append(q.cell[on_cut])
    p, w, c = cell_gauss(np.argwhere(classes != OUTSIDE), grid, order)
    return TrimQuadrature(np.concatenate([p, *points]), np.concatenate([w, *weights]),
                          np.concatenate([c, *cells]), classes)


def with_edges(surface: Any, edges: dict[str, str], classes: np.ndarray,
               fixed: np.ndarray | None = None) -> tuple[sp.csr_matrix, np.ndarray]:
    """``T = T_e E[K, F]`` and the free indices ``F`` (module docstring); the outer
    B-splines are tied to arrays of kept coefficients only, so ``E[K]`` never needs an
    eliminated one. ``fixed`` (a mask of the net, True: at rest) takes the fixed control
    points out of ``K`` as :func:`~splinedeform.boundary.build_constraints` does for an
    untrimmed net: a fixed inner B-spline stays at rest, and so does a fixed outer one
    (its coefficient is no longer the extension of the inner ones; the other outer ones
    are tied to arrays of free inner ones only); a fixed dead one (its support outside the
    region) was at rest already."""
    held = build_constraints(surface.basis_u, surface.basis_v, edges, fixed)
    kept = np.zeros(surface.shape, bool)
    kept.ravel()[held.free_index] = True
    try:
        web = web_basis(classes, surface_degrees(surface), allowed=kept,
                        knots=extension_knots(surface), weights=net_weights_of(surface))
    except InputError:
        if fixed is None or not np.any(fixed):
            raise
        n = surface_degrees(surface)
        raise InputError(f"the control points left free hold no {n[0] + 1}×{n[1] + 1} array "
                         "of inner B-splines (whose B-splines have a whole knot cell inside "
                         "the region), to which the outer ones are tied: free more points "
                         "or refine the net") from None
    inner = np.flatnonzero(web.inner.ravel())
    free = kept.ravel()[inner]
    E = web.extension.tocsr()[held.free_index]
    if abs(E[:, ~free]).sum() != 0:            # an outer B-spline among the eliminated
        raise InputError("a trim loop comes too close to a held edge of the rectangle or to "
                         "fixed control points: they and the extension of the loop's "
                         "B-splines meet; move the loop away, fix fewer points or refine "
                         "the net")
    return (held.T @ E[:, free]).tocsr(), inner[free]
