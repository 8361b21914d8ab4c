"""Loads brought to order one before the solve, the response scaled back after.

The response of a model at rest to loads ``F`` is linear in ``F``: ``d[s F] = s d[F]``.
A load of extreme magnitude (a denormal force such as ``1e-320`` keeps only a few
significant bits, and its products with basis integrals lose the rest) is solved as
``F / s`` with ``s = max |force_i|, |q|`` over the ``[[load]]`` tables, and every
displacement of the solution multiplied by ``s`` (energies by ``s²``): the answer is then
``s`` times the order-one answer, rounded once.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .solution import Energy

#: load magnitudes solved as they are; outside this range they are scaled to one
PLAIN_RANGE = (1e-100, 1e100)


def load_scale(scenario: Any) -> float:
    """``s = max |force_i|, |q|`` over the scenario's loads when it lies outside
    :data:`PLAIN_RANGE`, else 1 (no scaling); 1 without loads or when every one is zero."""
    sizes = [abs(float(x)) for spec in scenario.loads
             for x in (*(spec.force or ()), *(() if spec.q is None else (spec.q,)))]
    largest = max(sizes, default=0.0)
    if largest == 0.0 or not np.isfinite(largest) or PLAIN_RANGE[0] <= largest <= PLAIN_RANGE[1]:
        return 1.0
    return largest


class ScaledSolution:
    """A solution of the loads divided by ``scale``, read out as the solution of the loads:
    control nets ``p_rest + s (p - p_rest)``, displacements and velocities ``s d``,
    energies ``s² E``. Works for dynamic (``t`` given) and static solutions alike."""

    _SHARED = ("timings", "stats", "method", "t_end", "exact_between_frames", "rest",
               "readout")

    def __init__(self, unit: Any, scale: float) -> None:
        self.unit = unit
        self.scale = float(scale)

    def __getattr__(self, name: str) -> Any:
        if name in ScaledSolution._SHARED:
            return getattr(self.unit, name)
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")

    def _scaled_net(self, nets: Any) -> Any:
        rest = self.unit.rest.control_points
        return rest + self.scale * (np.asarray(nets) - rest)

    def control_points(self, *t: Any) -> Any:
        """``p_rest + s (p(t) - p_rest)``."""
        return self._scaled_net(self.unit.control_points(*t))

    def velocities(self, t: Any) -> Any:
        """``s v(t)``."""
        return self.scale * self.unit.velocities(t)

    def displacement(self, *args: Any) -> Any:
        """``s d(t, u, v)`` (dynamic) or ``s d(u, v)`` (static)."""
        return self.scale * self.unit.displacement(*args)

    def surface(self, *t: Any) -> Any:
        return self.unit.rest.with_control_points(self.control_points(*t), name="scaled")

    def energy(self, *t: Any) -> Energy:
        """``s²`` times the kinetic energy, strain energy and work."""
        e = self.unit.energy(*t)
        with np.errstate(under="ignore", over="ignore"):   # inf is refused by the caller
            s2 = np.float64(self.scale) ** 2
            return Energy(s2 * np.asarray(e.kinetic), s2 * np.asarray(e.strain),
                          s2 * np.asarray(e.work))
