"""Magnitudes of a scenario's lengths: each within the float range's usable part, and none
so far from the others that its digits are lost.

The energies multiply lengths up to their sixth power (a thin plate's ``w20`` term on a
net of size ``L`` under a load: ``L⁻² · L² · L²`` …, the shell's bending stiffness
``E t³``), so a length beyond ``10^±50`` overflows or underflows them; a length
:data:`RATIO_MAX` times another (a saddle's height against its size) leaves the smaller
without digits. A scenario with such a length is refused naming its key, before anything
is built, rather than failing later as a mass, boundary or eigenvalue problem.
"""

from __future__ import annotations

import math
from typing import Any

#: lengths of the built-in shapes (``angle`` is not a length)
LENGTH_KEYS = ("size", "radius", "length", "height", "R", "r")
#: usable magnitudes of a length
LENGTH_RANGE = (1e-50, 1e50)
#: largest ratio of two lengths of a shape
RATIO_MAX = 1e12
#: smallest shell thickness relative to the shape's largest length (``(t / L)²`` is the
#: ratio of bending to membrane stiffness; below ``1e-12`` it is lost in rounding)
THICKNESS_RATIO_MIN = 1e-6


def length_problems(surface: Any, material: Any) -> list[tuple[str, str]]:
    """``(key path, message)`` for each length of ``surface`` (a SurfaceSpec) and the shell
    thickness of ``material`` outside its usable range (see the module docstring)."""
    lengths: list[tuple[str, float]] = []
    for key in LENGTH_KEYS:
        value = surface.parameters.get(key)
        values = value if isinstance(value, tuple) else (value,)
        lengths += [(f"surface.{key}", abs(float(x))) for x in dict.fromkeys(values)
                    if isinstance(x, (int, float)) and x != 0]
    problems = []
    low, high = LENGTH_RANGE
    for key, size in lengths:
        if not low <= size <= high:
            problems.append((key, f"a length of {size:g} is outside {low:g} .. {high:g}, "
                                  "where the energies' powers of lengths stay within floating "
                                  "point; choose units that bring it nearer 1"))
    usable = [(k, s) for k, s in lengths if low <= s <= high]
    if len(usable) > 1:
        small, large = min(usable, key=lambda ks: ks[1]), max(usable, key=lambda ks: ks[1])
        if large[1] > RATIO_MAX * small[1]:
            # the extreme one of the two is the one farther from 1 (in decades)
            culprit, other = (large, small) if abs(math.log10(large[1])) >= \
                abs(math.log10(small[1])) else (small, large)
            problems.append((culprit[0], f"{culprit[0]} = {culprit[1]:g} against {other[0]} = "
                                         f"{other[1]:g}: a ratio beyond {RATIO_MAX:g} leaves "
                                         "the smaller length without digits"))
    thickness = getattr(material, "thickness", None)
    if isinstance(thickness, (int, float)) and thickness > 0:
        if not low <= thickness <= high:
            problems.append(("material.thickness", f"a thickness of {thickness:g} is outside "
                                                   f"{low:g} .. {high:g}; choose units that "
                                                   "bring it nearer 1"))
        elif usable:
            extent = max(s for _, s in usable)
            if thickness < THICKNESS_RATIO_MIN * extent:
                problems.append(("material.thickness", f"{thickness:g} is below "
                                 f"{THICKNESS_RATIO_MIN:g} times the shape's size {extent:g}: "
                                 "its bending stiffness (t / L)² would be lost in rounding"))
    return problems


def extent_problem(surface: Any, thickness: float | None) -> str | None:
    """For a surface read from a file (or a body of its faces): a message when its control
    nets' extent lies outside the usable range, or the shell ``thickness`` is too small for
    it; None when fine."""
    import numpy as np

    nets = surface.patches if hasattr(surface, "patches") else (surface,)
    P = np.concatenate([np.asarray(s.control_points, dtype=float).reshape(-1, 3)
                        for s in nets])
    extent = float(np.ptp(P, axis=0).max()) if P.size else 0.0
    low, high = LENGTH_RANGE
    if math.isfinite(extent) and extent > 0 and not low <= extent <= high:
        return (f"the surface spans {extent:g}, outside {low:g} .. {high:g}, where the energies' "
                "powers of lengths stay within floating point; rescale its coordinates")
    if thickness and extent > 0 and thickness < THICKNESS_RATIO_MIN * extent:
        return (f"material.thickness {thickness:g} is below {THICKNESS_RATIO_MIN:g} times the "
                f"surface's size {extent:g}: its bending stiffness (t / L)² would be lost")
    return None
