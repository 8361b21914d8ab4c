"""``surface.trim`` of a scenario: its loops as a :class:`~splinedeform.trim.TrimDomain`
on the built surface, and their edge conditions as boundary presets of the model."""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..trim import CircleLoop, PolygonLoop, SplineLoop, TrimDomain
from ..trim.loops import loops_cross
from ..trim.model_matrices import loop_keys
from ..trim.surface_trim import loop_outside


def _keys(trim: Any) -> tuple[str, ...]:
    """The loops' boundary keys: ``outer``, ``hole1``, … (all holes with ``rectangle``)."""
    keys = loop_keys(len(trim.loops) + 1)
    return keys[1:] if trim.rectangle else keys[:-1]


def loop_labels(trim: Any) -> list[str]:
    """Each loop's name as given, else its boundary key (``outer``, ``hole1``, …)."""
    return [loop.name or key for loop, key in zip(trim.loops, _keys(trim))]


def trimmed(scenario: Any, surface: Any) -> Any:
    """``surface`` trimmed to ``surface.trim`` (unchanged without one); a problem names the
    loop's key (``surface.trim.loops[2]``) and, for two loops, both their names."""
    trim = scenario.surface.trim
    if trim is None:
        return surface
    labels = loop_labels(trim)
    where = [f"surface.trim.loops[{k}]" for k in range(1, len(labels) + 1)]
    for k, label in enumerate(labels):
        if label in labels[:k]:
            raise scenario.error(where[k] + ".name", f"loop name {label!r} is used twice")
    loops = []
    for k, spec in enumerate(trim.loops):
        try:
            loop = _loop(spec)
        except InputError as exc:
            raise scenario.error(where[k], str(exc)) from None
        problem = loop_outside(surface, loop)
        if problem:
            raise scenario.error(where[k], f"loop {labels[k]!r} {problem}")
        for j, other in enumerate(loops):
            if loops_cross(other, loop):
                raise scenario.error(where[k], f"loop {labels[k]!r} crosses or touches loop "
                                     f"{labels[j]!r}; trim loops must not meet")
        loops.append(loop)
    (_, lu), (_, lv) = surface.domain
    if trim.rectangle:
        loops.insert(0, PolygonLoop([[0.0, 0.0], [lu, 0.0], [lu, lv], [0.0, lv]]))
    try:
        domain = TrimDomain(loops[0], tuple(loops[1:]))
    except InputError as exc:
        outer = "the rectangle" if trim.rectangle else f"the first loop, {labels[0]!r},"
        raise scenario.error("surface.trim.loops", f"{exc} ({outer} is the outer loop; the "
                             "others are its holes)") from None
    try:
        return surface.with_trim(domain)
    except InputError as exc:
        raise scenario.error("surface.trim", str(exc)) from None


def _loop(spec: Any) -> Any:
    if spec.circle is not None:
        return CircleLoop(spec.circle.centre, spec.circle.radius)
    if spec.spline is not None:
        return SplineLoop(spec.spline.points, spec.spline.degree)
    return PolygonLoop(spec.polygon)


def loop_presets(scenario: Any) -> dict[str, str]:
    """The loops' edge conditions under their boundary keys (``outer``, ``hole1``, …)."""
    trim = scenario.surface.trim
    if trim is None:
        return {}
    return dict(zip(_keys(trim), (loop.edge for loop in trim.loops)))
