"""The per-mode outputs of a modes solve, of one surface or of a body: which files, the
frames of each mode, and writing them.

Beside the run's own frames (those of mode 1) a modes solve of ``K`` modes writes, with the
formats that ask for it (docs/outputs.md):

* ``vtu``: ``<name>_modes.vtu``, the rest mesh with one displacement field ``mode_k`` per
  mode (a body's: every face, welded, :func:`splinedeform.export.write_body_mode_fields`);
* ``json`` / ``npz``: ``<name>_mode<k>_nets.json/.npz`` for every mode, the control nets
  over one period (a body's: every face's, :mod:`splinedeform.export.body_nets`);
* for each mode ``k`` of ``output.animate_modes`` but the first: ``<name>_mode<k>.gif/.mp4``
  (gif, mp4) and the ParaView series ``<name>_mode<k>.pvd`` + ``<name>_mode<k>_0000.vtu`` …
  (vtu; a body's welded, a shell's with its stresses), as the run's own for mode 1.

Mode ``k``'s frames are ``P_rest + sin(2π φ) D_k`` at the phases ``φ`` of the frames, on
every patch of a body (:func:`mode_frames`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from .scenario.body import is_body

if TYPE_CHECKING:
    from .outputs import Stages
    from .pipeline import RunResult

#: ``animate(path, nets, what, label)``: write an animation of ``nets`` to ``path``
Animate = Callable[[Path, Any, str, str], None]


def mode_count(result: RunResult) -> int:
    """How many modes the solve computed (0 without modes)."""
    return 0 if result.omegas is None or result.mode_nets is None else len(result.omegas)


def mode_file_names(result: RunResult) -> list[str]:
    """The per-mode files of a modes solve, in the order written (module docstring)."""
    from .export import frame_file_names

    s = result.scenario
    if s.solve.kind != "modes" or not mode_count(result):
        return []
    formats, name = s.output.formats, s.name
    names = [f"{name}_modes.vtu"] if "vtu" in formats else []
    names += [f"{name}_mode{k}_nets.{ext}" for k in range(1, mode_count(result) + 1)
              for ext in ("json", "npz") if ext in formats]
    for k in animated_modes(result):
        if k != 1 and "vtu" in formats:
            names += [*frame_file_names(f"{name}_mode{k}", len(result.times)),
                      f"{name}_mode{k}.pvd"]
        names += [f"{name}_mode{k}.{ext}" for ext in ("gif", "mp4")
                  if k != 1 and ext in formats]
    return names


def animated_modes(result: RunResult) -> tuple[int, ...]:
    """``output.animate_modes`` (mode numbers from 1), mode 1 when not given."""
    return tuple(result.scenario.output.animate_modes or (1,))


def mode_frames(result: RunResult, k: int) -> Any:
    """Control nets of mode ``k`` (from 1) over one period: ``P_rest + sin(2π φ) D_k`` at the
    phases ``φ`` of the frames (the frames of a modes solve are those of mode 1); a body's
    is a list with the ``(F, n_u, n_v, 3)`` frames of each patch."""
    phase = np.sin(2.0 * np.pi * np.asarray(result.times, dtype=float))[:, None, None, None]
    if is_body(result.built.surface):
        return [rest + phase * D[k - 1] for rest, D in zip(result.rest_net, result.mode_nets)]
    return result.rest_net + phase * result.mode_nets[k - 1]


def mode_label(result: RunResult, k: int) -> str:
    """The animation's frame label of mode ``k``: ``mode k (ω = …), phase``."""
    return f"mode {k} (ω = {float(result.omegas[k - 1]):.5g}), phase"


def viewer_modes(result: RunResult) -> tuple[Any, Any] | None:
    """``(ω, D)`` for the viewer's mode menu of a modes solve (None otherwise): the modes'
    frequencies and net displacements (a body's: one array per patch)."""
    if result.scenario.solve.kind != "modes" or not mode_count(result):
        return None
    return result.omegas, result.mode_nets


def write_mode_files(result: RunResult, folder: Path, stages: Stages, animate: Animate) -> None:
    """The files of :func:`mode_file_names`; ``animate`` writes the animations."""
    from . import export

    s = result.scenario
    formats, name = s.output.formats, s.name
    if "vtu" in formats:
        with stages.stage("mode fields .vtu"):
            result.outputs.append(("mode fields .vtu", _mode_fields(
                result, folder / f"{name}_modes.vtu")))
    wanted = [ext for ext in export.CONTROL_NET_FORMATS if ext in formats]
    if wanted:
        with stages.stage("mode nets"):
            for k in range(1, mode_count(result) + 1):
                for path in _mode_nets(result, folder, f"{name}_mode{k}_nets", k, wanted):
                    result.outputs.append((f"mode {k} nets {path.suffix}", path))
    for k in animated_modes(result):
        if k == 1:
            continue
        if "vtu" in formats:
            with stages.stage(f"mode {k} series"):
                result.outputs.append((f"mode {k} series .pvd", _mode_series(
                    result, folder, f"{name}_mode{k}", mode_frames(result, k))))
        for ext in ("gif", "mp4"):
            if ext in formats:
                animate(folder / f"{name}_mode{k}.{ext}", mode_frames(result, k), f"mode {k}",
                        mode_label(result, k))


def _mode_fields(result: RunResult, path: Path) -> Path:
    from . import export

    body, res = result.built.surface, result.scenario.output.resolution
    if is_body(body):
        from .outputs_body import orientation

        return export.write_body_mode_fields(path, list(body.patches), result.mode_nets, res,
                                             orientation(result))
    return export.write_mode_fields(path, body, result.mode_nets, resolution=res)


def _mode_nets(result: RunResult, folder: Path, stem: str, k: int, formats: list[str]
               ) -> list[Path]:
    from . import export

    body = result.built.surface
    if is_body(body):
        from .export.body_nets import write_body_control_nets
        from .outputs_body import face_numbers, orientation

        return write_body_control_nets(folder, stem, list(body.patches), face_numbers(result),
                                       result.times, mode_frames(result, k), formats=formats,
                                       orientation=orientation(result))
    return export.write_control_nets(folder, stem, body, result.times, mode_frames(result, k),
                                     formats=formats)


def _mode_series(result: RunResult, folder: Path, stem: str, nets: Any) -> Path:
    """Mode ``k``'s ParaView series (``nets`` its frames), a shell's with its stresses."""
    from . import export
    from .export.shell_fields import is_shell, stress_fields

    body, model = result.built.surface, result.built.model
    res, rest = result.scenario.output.resolution, result.rest_net
    if is_body(body):
        from .export.body import write_body_series
        from .outputs_body import orientation
        from .outputs_body_shell import body_stress_fields

        fields = body_stress_fields(model, rest, nets, res) if is_shell(model) else None
        return write_body_series(folder, stem, list(body.patches), rest, result.times, nets,
                                 res, fields, orientation(result))
    fields = stress_fields(model, rest, nets, res) if is_shell(model) else None
    return export.write_time_series(folder, stem, body, rest, result.times, nets,
                                    resolution=res, fields=fields)
