"""Read-out of the Kirchhoff–Love shell's solutions: control nets and stresses.

A shell's state is its reduced unknowns ``d_free (..., n_free)`` (x, y and z coupled, the
rows of ``T`` interleaved, :mod:`splinedeform.readout` with ``per_point = 3``); control
points are ``p(t) = p_rest + reshape(T d_free(t))``. The solutions are the model's
(:class:`~splinedeform.solution.StaticSolution`, :class:`~splinedeform.modal_solution.ModalSolution`);
what the shell adds is the stresses of a displacement net (:func:`.shell_stress.stresses`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np  # noqa: F401
from numpy.typing import ArrayLike, NDArray

from ..readout import BodyReadout, Readout
from .shell_body import patch_index
from .shell_stress import ShellStresses, stresses

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShellReadout(Readout):
    """:class:`~splinedeform.readout.Readout` of a shell on one surface, with its material."""

    material: Any = None

    def stresses(self, displacement: ArrayLike, u: ArrayLike, v: ArrayLike,
                 at_poles: str = "raise", patch: int | None = None) -> ShellStresses:
        """Stresses of a displacement net ``(..., n_u, n_v, 3)`` at ``u, v``
        (:func:`.shell_stress.stresses`)."""
        return stresses(self.surface, self.material, displacement, u, v, at_poles)


@dataclass(frozen=True)
class ShellBodyReadout(BodyReadout):
    """:class:`~splinedeform.readout.BodyReadout` of a shell body, with its material."""

    material: Any = None

    def stresses(self, displacement: list[Array], u: ArrayLike, v: ArrayLike,
                 at_poles: str = "raise", patch: int | None = None) -> ShellStresses:
        """Stresses of the per-patch displacement nets at ``u, v`` of ``patch``."""
        p = patch_index(len(self.surfaces), patch)
        return stresses(self.surfaces[p], self.material, displacement[p], u, v, at_poles)

