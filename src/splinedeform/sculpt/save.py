""""Save" of a sculpting session: the pushes as the ``[[load]]`` tables of a scenario.

Each grab becomes one piecewise point load at the sample point it held (:mod:`.grabs`); on
a body the load names its face (``face = k``, the file's face number, ``at`` in that face's
parameters), so ``splinedeform run`` replays the session on the same faces. A surface read
from a file (``file``, ``cad``) is named relative to the saved scenario, copied beside it
when it lies outside its folder (:func:`portable`).
"""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path
from typing import Any, Sequence

from ..errors import InputError
from ..scenario import with_overrides
from ..scenario.spec import Scenario
from .grabs import chain_tables, grab_chains
from .messages import PushMessage, SaveMessage
from .modal import SculptBasis
from .trimmed import outside_words

MAX_PROBES = 8
"""Grabbed points written as probes of the saved scenario (the first ones)."""


def check_pushes(basis: SculptBasis, pushes: Sequence[PushMessage]) -> None:
    """Every push on a sample point of ``basis``, released after it started."""
    for n, push in enumerate(pushes, start=1):
        check_index(basis, push.index, f"pushes[{n}].index")
        if push.t_off is not None and not push.t_off > push.t_on:
            raise InputError(f"pushes[{n}]: t_off = {push.t_off} must be after t_on = {push.t_on}")


def check_index(basis: SculptBasis, index: int, what: str) -> None:
    """``index`` names a sample point of ``basis`` inside its trims."""
    count = basis.sample_count
    if not 0 <= index < count:
        raise InputError(f"{what} = {index} is not a sample point (0 .. {count - 1})")
    if basis.trimmed is not None and not basis.trimmed.inside[index]:
        patch, u, v = basis.sample_point(index)
        raise InputError(f"{what} = {index}: {outside_words(basis.patches[patch], u, v)}")


def face_numbers(basis: SculptBasis) -> list[int]:
    """The file's face number of each patch (the patch index where there is no file)."""
    return list(getattr(getattr(basis.model, "body", None), "faces", range(len(basis.patches))))


def session_scenario(scenario: Scenario, basis: SculptBasis, message: SaveMessage,
                     resolution: int) -> Scenario:
    """``scenario`` with the pushes of ``message`` as loads (module text), probes at the
    grabbed points of one surface (a body's probes are its faces' centres)."""
    check_pushes(basis, message.pushes)
    faces = face_numbers(basis)
    loads: list[dict[str, Any]] = []
    probes: list[list[float]] = []
    for chain in grab_chains(message.pushes):
        patch, u, v = basis.sample_point(chain[0].index)
        tables = chain_tables(chain, [u, v])
        if basis.is_body:
            tables = [{**table, "face": faces[patch]} for table in tables]
        elif [u, v] not in probes and len(probes) < MAX_PROBES:
            probes.append([u, v])
        loads += tables
    if not loads:
        raise InputError("nothing to save: every push of the session has zero force")
    overrides: dict[str, Any] = {
        "load": loads,
        "title": f"sculpted: {scenario.title or scenario.name}",
        "solve": {"kind": "dynamic", "method": "analytic", "t_end": message.t_end,
                  "frames": 101, "modes": min(6, basis.model.n_free)},
        "output": {"formats": ["report", "images", "viewer"], "resolution": min(resolution, 64)},
    }
    if probes:
        overrides["output"]["probes"] = probes
    return with_overrides(scenario, overrides, origin="sculpt save")


def net_words(basis: SculptBasis) -> str:
    """The control net in words for the saved file's header."""
    sizes = [f"{s.shape[0]}x{s.shape[1]}" for s in basis.patches]
    if not basis.is_body:
        return f"{sizes[0]} control points"
    return f"{len(sizes)} faces of {', '.join(sizes)} control points"


def portable(scenario: Scenario, save_path: Path) -> Scenario:
    """``scenario`` with its surface file (if any) named relative to the save file's
    folder, which ``splinedeform run`` reads without ``--allow-outside-paths``: the
    file as it is when it lies in that folder or below, else a copy beside the save."""
    from ..export import write_with

    source = scenario.surface.path
    if source is None:
        return scenario
    source = Path(source).resolve()
    folder = save_path.parent.resolve()
    if not source.is_relative_to(folder):
        target = folder / source.name
        if target.exists() and not same_file(target, source):
            target = folder / f"{save_path.stem}-{source.name}"
        if not (target.exists() and same_file(target, source)):
            write_with(target, lambda tmp: shutil.copyfile(source, tmp))
        source = target
    relative = Path(source.relative_to(folder).as_posix())
    return dataclasses.replace(scenario,
                               surface=dataclasses.replace(scenario.surface, path=relative))


def same_file(a: Path, b: Path) -> bool:
    """Whether two regular files hold the same bytes (anything else in their place, such as
    a named pipe, is not the same file and is never read)."""
    from ..input_files import MAX_TEXT_BYTES, open_input

    if not (a.is_file() and b.is_file()) or a.stat().st_size != b.stat().st_size:
        return False
    with open_input(a, "file", MAX_TEXT_BYTES * 32) as fa, \
            open_input(b, "file", MAX_TEXT_BYTES * 32) as fb:
        return fa.read() == fb.read()
