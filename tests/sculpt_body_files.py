"""A body of two flat faces for the sculpting tests, written as one sewn STEP shell.

Face 0 is ``[0, 1] × [0, 1]``, face 1 ``[1, 2] × [0, 1]`` (cubic, 3 × 3 spans, control
points at the Greville abscissae, so ``x(u, v) = (x0 + u, v, 0)``); they share the edge
``x = 1``: face 0's ``u1`` is face 1's ``u0``, with the same ``v``. :data:`BODY` opens
every face of ``two.step`` with every boundary edge clamped and membrane tension.
"""

from __future__ import annotations

from pathlib import Path

from body_patches import flat_patch

from splinedeform.export.body import write_body_step
from splinedeform.surface import Surface

BODY = """
title = "two faces"
[surface]
shape = "cad"
path = "two.step"
[material]
damping = 2.0
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
u1 = "clamped"
v0 = "clamped"
v1 = "clamped"
[solve]
kind = "modes"
"""


def two_faces(folder: Path) -> list[Surface]:
    """The two faces as one shell of ``folder/two.step`` (in millimetres)."""
    faces = [flat_patch((0.0, 1.0), (0.0, 1.0), (3, 3)), flat_patch((1.0, 2.0), (0.0, 1.0), (3, 3))]
    write_body_step(folder / "two.step", faces, [f.control_points for f in faces], "mm",
                    shell=True)
    return faces
