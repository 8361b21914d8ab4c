"""Undo and redo of a sculpting session: the bases it had, kept whole, and "bake".

Every re-solve and every bake replaces the session's basis; the one replaced is kept (up to
:data:`MAX_UNDO`), so undo and redo switch back to it exactly: the same scenario, modes and
static correction, under the same version number (a version names one basis), nothing
solved again. A new re-solve or bake after an undo drops what could have been redone.

Bake makes the current shape the rest shape: the control net ``P + d`` with
``d = T Φ_net q`` (the page's modal displacement ``q``, ``(k, 3)``) becomes the model's
initial surface, written as a control-net file beside the save file, whose knot vectors it
keeps (:func:`baked_scenario`); the modes are then solved again on it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..scenario import with_overrides
from ..scenario.spec import Scenario
from .correction import StaticCorrection
from .modal import SculptBasis

MAX_UNDO = 20
"""Earlier bases kept for undo (each holds its modes: memory, not time)."""


@dataclass(frozen=True)
class BasisState:
    """One basis of the session with what it was solved from."""

    scenario: Scenario
    basis: SculptBasis
    correction: StaticCorrection
    version: int


@dataclass
class History:
    """The bases before the current one (``past``, newest last) and after it (``future``)."""

    past: list[BasisState] = field(default_factory=list)
    future: list[BasisState] = field(default_factory=list)

    def replaced(self, old: BasisState) -> None:
        """``old`` was replaced by a new basis: it can be undone to; nothing can be redone."""
        self.past.append(old)
        del self.past[:-MAX_UNDO]
        self.future.clear()

    def back(self, current: BasisState) -> BasisState:
        """The basis before ``current`` (which becomes redoable)."""
        if not self.past:
            raise InputError("nothing to undo")
        self.future.append(current)
        return self.past.pop()

    def forward(self, current: BasisState) -> BasisState:
        """The basis undone last (``current`` becomes undoable again)."""
        if not self.future:
            raise InputError("nothing to redo")
        self.past.append(current)
        return self.future.pop()


def baked_net(basis: SculptBasis, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The control net ``P + T Φ_net q`` of the modal state ``q`` (``3 k`` numbers,
    mode-major), ``(n_u, n_v, 3)``."""
    surface = basis.model.surface
    q = np.asarray(q, dtype=float).ravel()
    if q.size != 3 * basis.lam.size:
        raise InputError(f"q must hold 3 coordinates for each of the {basis.lam.size} modes "
                         f"({3 * basis.lam.size} numbers), got {q.size}")
    d = np.asarray(basis.phi_net @ q.reshape(-1, 3)).reshape(surface.control_points.shape)
    return surface.control_points + d


def baked_scenario(scenario: Scenario, basis: SculptBasis, net: NDArray[np.float64],
                   folder: Path, stem: str) -> tuple[Scenario, Path]:
    """``scenario`` on the surface of control net ``net`` (same bases), written to
    ``folder/stem.json``; the scenario reads it from ``folder`` (its directory then)."""
    from ..export import write_control_nets

    surface = basis.model.surface
    path, = write_control_nets(folder, stem, surface, [0.0], net[None], formats=("json",))
    moved = dataclasses.replace(scenario, directory=folder.resolve())
    table: dict[str, Any] = {"shape": "file", "path": path.name}
    return with_overrides(moved, {"surface": table}, origin="sculpt bake"), path
