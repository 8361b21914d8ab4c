"""Undo and redo of a sculpting session: the bases it had, kept whole, and "bake".

Every re-solve and every bake replaces the session's basis; the one replaced is kept (up to
:data:`MAX_UNDO`), so undo and redo switch back to it exactly: the same scenario, modes and
static correction, under the same version number (a version names one basis), nothing
solved again. A new re-solve or bake after an undo drops what could have been redone.

Bake makes the current shape the rest shape: the control net ``P + d`` with
``d = T Φ_net q`` (the page's modal displacement ``q``, ``(k, 3)``) becomes the model's
initial surface, written as a control-net file beside the save file, whose knot vectors it
keeps (:func:`baked_scenario`); the modes are then solved again on it. A body's faces are
written together as one STEP shell, sewn where they meet, so that the file read back has
the body's shared edges (:func:`splinedeform.export.body.write_body_step`).
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


def baked_nets(basis: SculptBasis, q: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """Per patch the control net ``P + T Φ_net q`` of the modal state ``q`` (``3 k``
    numbers, mode-major), each ``(n_u, n_v, 3)``."""
    q = np.asarray(q, dtype=float).ravel()
    if q.size != 3 * basis.lam.size:
        raise InputError(f"q must hold 3 coordinates for each of the {basis.lam.size} modes "
                         f"({3 * basis.lam.size} numbers), got {q.size}")
    return basis.split_net(basis.rest_net() + basis.phi_net @ q.reshape(-1, 3))


def baked_net(basis: SculptBasis, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The control net ``P + T Φ_net q`` of a single surface's modal state ``q``,
    ``(n_u, n_v, 3)`` (:func:`baked_nets`)."""
    net, = baked_nets(basis, q)
    return net


def baked_scenario(scenario: Scenario, basis: SculptBasis, nets: list[NDArray[np.float64]],
                   folder: Path, stem: str) -> tuple[Scenario, Path]:
    """``scenario`` on the surface of control nets ``nets`` (same bases), written to
    ``folder/stem.json`` (one surface, with its ``[surface.trim]`` if it has one) or ``folder/stem.step`` (a body: every face in one
    shell, in the body's unit, read back with ``faces = "all"``); the scenario reads it
    from ``folder`` (its directory then)."""
    from ..export import write_control_nets

    moved = dataclasses.replace(scenario, directory=folder.resolve())
    if basis.is_body:
        return _baked_body(moved, basis, nets, folder / f"{stem}.step")
    surface = basis.model.surface
    trim = scenario.raw.get("surface", {}).get("trim")
    if surface.trim is not None and trim is None:
        raise InputError("this face's trims come from its CAD file, and a baked net file "
                         "does not hold them yet: bake is for an untrimmed face or a trim "
                         "given by hand ([surface.trim])")
    path, = write_control_nets(folder, stem, surface, [0.0], nets[0][None], formats=("json",))
    table: dict[str, Any] = {"shape": "file", "path": path.name}
    if trim is not None:                    # a trim given by hand: the baked net keeps it
        table["trim"] = trim
    return with_overrides(moved, {"surface": table}, origin="sculpt bake"), path


def _baked_body(scenario: Scenario, basis: SculptBasis, nets: list[NDArray[np.float64]],
                path: Path) -> tuple[Scenario, Path]:
    """The body's faces with ``nets`` as one sewn STEP shell (patch ``p`` its face ``p``;
    the refinement already done, so none asked again) and ``scenario`` on it: the faces
    named by ``boundary.faces``, ``boundary.faces_free_points`` and by loads renumbered
    to the new file's."""
    from ..export.body import write_body_step

    faces = list(getattr(basis.model.body, "faces", range(len(basis.patches))))
    write_body_step(path, basis.patches, nets, basis.units, shell=True,
                    orientation=getattr(basis.model.body, "orientation", None))
    number = {face: patch for patch, face in enumerate(faces)}
    overrides: dict[str, Any] = {"surface": {"shape": "cad", "path": path.name, "faces": "all"}}
    for key in ("faces", "faces_free_points"):      # edge presets, painted sets
        named = scenario.raw.get("boundary", {}).get(key)
        if named:
            overrides[f"boundary.{key}"] = {str(number[int(k)]): v for k, v in named.items()}
    loads = scenario.raw.get("load")
    if loads:
        overrides["load"] = [{**t, "face": number[int(t["face"])]} if "face" in t else t
                             for t in loads]
    return with_overrides(scenario, overrides, origin="sculpt bake"), path
