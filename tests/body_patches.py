"""Patches for the body tests: flat squares on open knots, split along C0 knot lines.

A patch of ``[x0, x1] × [y0, y1]`` on open knots with ``cells`` equal spans per direction,
its control points at the Greville abscissae (so ``x(u, v) = (x0 + u, y0 + v, 0)``, or
mirrored in a reversed direction), and the single patch of the whole square whose knot
vectors repeat the split lines ``degree`` times: the same discrete space as the split body.
"""

from __future__ import annotations

import numpy as np

from splinedeform.knots import KnotVectorBasis
from splinedeform.surface import Surface

DEGREE = 3


def open_knots(length: float, cells: int, degree: int = DEGREE) -> np.ndarray:
    return np.concatenate([np.zeros(degree), np.linspace(0.0, length, cells + 1),
                           np.full(degree, length)])


def flat_patch(x: tuple[float, float], y: tuple[float, float], cells: tuple[int, int],
               reverse_u: bool = False, reverse_v: bool = False) -> Surface:
    """``[x0, x1] × [y0, y1]`` at ``z = 0``; ``reverse_u``: ``x = x1 - u``, etc."""
    bu = KnotVectorBasis(DEGREE, open_knots(x[1] - x[0], cells[0]))
    bv = KnotVectorBasis(DEGREE, open_knots(y[1] - y[0], cells[1]))
    gu, gv = bu.greville(), bv.greville()
    X = x[1] - gu if reverse_u else x[0] + gu
    Y = y[1] - gv if reverse_v else y[0] + gv
    net = np.stack(list(np.meshgrid(X, Y, indexing="ij")) + [np.zeros((gu.size, gv.size))], axis=-1)
    return Surface(net, bu, bv)


def split_square(splits: tuple[int, int], cells: int) -> Surface:
    """The unit square on one patch whose knots repeat ``i / splits`` ``DEGREE`` times (C0
    lines), ``cells`` spans in each part."""
    def knots(parts: int) -> np.ndarray:
        inner = [np.linspace(k / parts, (k + 1) / parts, cells + 1)[1:-1] for k in range(parts)]
        lines = [np.full(DEGREE, k / parts) for k in range(1, parts)]
        middle = [x for pair in zip(inner, lines + [np.zeros(0)]) for x in pair]
        return np.concatenate([np.zeros(DEGREE + 1)] + middle + [np.ones(DEGREE + 1)])
    bu = KnotVectorBasis(DEGREE, knots(splits[0]))
    bv = KnotVectorBasis(DEGREE, knots(splits[1]))
    gu, gv = bu.greville(), bv.greville()
    net = np.stack(list(np.meshgrid(gu, gv, indexing="ij")) + [np.zeros((gu.size, gv.size))], axis=-1)
    return Surface(net, bu, bv)


def hemisphere(radius: float, start: float, cells: int = 8) -> Surface:
    """Longitudes ``[start, start + π]`` (``u``) and polar angle ``v ∈ [0, π]`` (``v0`` at the
    south pole, outward normal) of the sphere of ``radius``, interpolated by a bicubic patch
    of ``cells × cells`` spans: a patch with a pole at each end of ``v``."""
    from math import pi

    from splinedeform.shapes import from_function

    def f(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        phi = u + start
        return radius * np.stack([np.sin(v) * np.cos(phi), np.sin(v) * np.sin(phi),
                                  -np.cos(v)], axis=-1)
    return from_function(f, cells=(cells, cells), domain=((0, pi), (0, pi)))


def rhino3dm_box(folder, units: str, size=(1.0, 2.0, 3.0)):
    """``box.3dm`` in ``folder``: rhino3dm's box ``[0, size]`` (6 bilinear faces of one
    Brep) in the unit named ``units`` (a ``rhino3dm.UnitSystem`` member); its path."""
    import rhino3dm as r3

    path = folder / "box.3dm"
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = getattr(r3.UnitSystem, units)
    model.Objects.AddBrep(r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, *size))))
    assert model.Write(str(path), 7)
    return path
