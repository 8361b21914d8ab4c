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


# -- the unit square as two halves, and the same as a two-face .3dm with a scenario --------
HALF_CELLS = 3
N = HALF_CELLS + DEGREE   # each half: a 6 × 6 net
ROWS = 2 * N - 1          # the single patch: 11 rows along u (the C0 line's row shared)


def halves() -> list[Surface]:
    """The unit square as two patches, the right one reversed in u (its u1 at x = 0.5)."""
    return [flat_patch((0, 0.5), (0, 1), (HALF_CELLS, HALF_CELLS)),
            flat_patch((0.5, 1), (0, 1), (HALF_CELLS, HALF_CELLS), reverse_u=True)]


def single_row(patch: int, i: int) -> int:
    """The row of the single patch (:func:`split_square`) of row ``i`` of ``patch``."""
    return i if patch == 0 else ROWS - 1 - i


def halves_3dm(path):
    """The two halves as one Brep of two faces (face 0 the left half) written to ``path``."""
    import splinedeform as sd
    from splinedeform.export.body import write_body_3dm

    patches = halves()
    return write_body_3dm(path, patches, [s.control_points for s in patches],
                          body=sd.Body(patches))


def halves_scenario(folder, source, material: str, boundary: str,
                    formats: str = '"json", "report"'):
    """``folder/two.toml``: the ``.3dm`` ``source`` (copied beside it) under ``material``
    (the lines of ``[material]``) and ``boundary`` (those of ``[boundary]``), a uniform
    load ``(0, 0, -1)``, a static solve, the ``formats`` at resolution 5."""
    import shutil

    shutil.copy(source, folder / source.name)
    path = folder / "two.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{source.name}"\n'
                    f'[material]\n{material}[boundary]\n{boundary}'
                    '[[load]]\nkind = "uniform"\nforce = [0.0, 0.0, -1.0]\n'
                    '[solve]\nkind = "static"\n'
                    f'[output]\nformats = [{formats}]\nresolution = 5\n')
    return path
