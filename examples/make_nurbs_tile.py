"""Write ``examples/nurbs_tile.3dm``: the paper's roof tile as an exact NURBS surface.

The tile of ``tile_pressure_critical.toml`` (a 90° arc of radius 1 in the x-z plane, crest
at z = 1, swept 2 units along y), made exactly: one rational quadratic arc (weights
``1, √½, 1``) times a quadratic line, refined by knot insertion to 8 × 8 spans, and written
with splinedeform's own ``.3dm`` export (the ``cad`` extra). ``nurbs_tile_pressure.toml``
starts from it.

Usage: ``python examples/make_nurbs_tile.py`` (from anywhere; writes next to this file).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from splinedeform.cad import NurbsPatch, refine, write_3dm

SPANS = 8


def nurbs_tile(spans: int = SPANS) -> NurbsPatch:
    """Exact tile: the arc from 135° to 45° (crest u = 1/2), y = v on [0, 2]."""
    s = np.sqrt(0.5)
    arc = np.array([[-s, 0.0, s], [0.0, 0.0, 2 * s], [s, 0.0, s]])   # middle: tangents meet
    points = np.stack([arc + [0.0, y, 0.0] for y in (0.0, 1.0, 2.0)], axis=1)
    weights = np.outer([1.0, s, 1.0], [1.0, 1.0, 1.0])
    clamped = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    return refine(NurbsPatch((2, 2), clamped, 2.0 * clamped, points, weights), spans)


def main() -> Path:
    path = write_3dm(Path(__file__).resolve().parent / "nurbs_tile.3dm", [nurbs_tile()],
                     names=["nurbs tile"])
    print(f"wrote {path}")
    return path


if __name__ == "__main__":
    main()
