"""Write ``examples/nurbs_tile.3dm``: the paper's roof tile as an exact NURBS surface.

The tile of ``tile_pressure_critical.toml`` (a 90° arc of radius 1 in the x-z plane, crest
at z = 1, swept 2 units along y), made exactly: one rational quadratic arc (weights
``1, √½, 1``) times a quadratic line, refined by knot insertion to 8 × 8 spans, and written
with splinedeform's own ``.3dm`` export (the ``cad`` extra). ``nurbs_tile_pressure.toml``
starts from it.

openNURBS stamps every file with the time it was written and gives every object a new
random id, so a rewrite changes the bytes even when nothing else changed: the file is
written only when it is missing or its surface differs from :func:`nurbs_tile` (degrees,
knots, control points, weights, object name), and left untouched otherwise. ``--force``
writes it anyway.

Usage: ``python examples/make_nurbs_tile.py [--force]`` (from anywhere; writes next to this
file).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from splinedeform.cad import NurbsPatch, read_3dm, refine, write_3dm
from splinedeform.errors import InputError

SPANS = 8
NAME = "nurbs tile"
PATH = Path(__file__).resolve().parent / "nurbs_tile.3dm"
#: relative difference of knots, points and weights below which two tiles are the same
#: (a .3dm stores the points in homogeneous form w·P, so reading back costs a few ulps)
SAME = 1e-12


def nurbs_tile(spans: int = SPANS) -> NurbsPatch:
    """Exact tile: the arc from 135° to 45° (crest u = 1/2), y = v on [0, 2]."""
    s = np.sqrt(0.5)
    arc = np.array([[-s, 0.0, s], [0.0, 0.0, 2 * s], [s, 0.0, s]])   # middle: tangents meet
    points = np.stack([arc + [0.0, y, 0.0] for y in (0.0, 1.0, 2.0)], axis=1)
    weights = np.outer([1.0, s, 1.0], [1.0, 1.0, 1.0])
    clamped = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    return refine(NurbsPatch((2, 2), clamped, 2.0 * clamped, points, weights), spans)


def is_current(path: Path, patch: NurbsPatch, name: str = NAME) -> bool:
    """Whether ``path`` holds just ``patch``, named ``name``, to :data:`SAME`."""
    import rhino3dm

    if not path.is_file():
        return False
    model = rhino3dm.File3dm.Read(str(path))
    if model is None or len(model.Objects) != 1 or model.Objects[0].Attributes.Name != name:
        return False
    try:
        old = read_3dm(path, 0)
    except InputError:
        return False
    pairs = [(old.knots_u, patch.knots_u), (old.knots_v, patch.knots_v),
             (old.points, patch.points), (old.weights, patch.weights)]
    return tuple(old.degrees) == tuple(patch.degrees) and all(
        np.shape(a) == np.shape(b)
        and np.allclose(a, b, rtol=0.0, atol=SAME * max(1.0, float(np.abs(b).max())))
        for a, b in pairs)


def main(path: Path = PATH, force: bool = False) -> tuple[Path, bool]:
    """Write the tile to ``path`` unless it holds it already; returns ``(path, written)``."""
    patch = nurbs_tile()
    if not force and is_current(path, patch):
        print(f"unchanged: {path} holds the tile already")
        return path, False
    write_3dm(path, [patch], names=[NAME])
    print(f"wrote {path}")
    return path, True


if __name__ == "__main__":
    main(force="--force" in sys.argv[1:])
