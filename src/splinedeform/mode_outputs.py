"""The per-mode outputs of a modes solve: which files, and the frames of each mode.

A modes solve writes, beside the run's own frames (those of mode 1), ``<name>_modes.vtu``
with one displacement field per mode, the control nets of each mode over one period and an
animation of each mode that ``output.animate_modes`` names (docs/outputs.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .pipeline import RunResult


def mode_file_names(result: RunResult) -> list[str]:
    """The per-mode files of a modes solve: ``<name>_modes.vtu`` (vtu), the frames of each
    mode ``<name>_mode<k>_nets.json/.npz`` (json, npz) and the animation of each mode of
    ``output.animate_modes`` but the first, ``<name>_mode<k>.gif/.mp4`` (gif, mp4)."""
    s = result.scenario
    if s.solve.kind != "modes" or result.mode_nets is None:
        return []
    formats, name = s.output.formats, s.name
    names = [f"{name}_modes.vtu"] if "vtu" in formats else []
    names += [f"{name}_mode{k}_nets.{ext}" for k in range(1, len(result.mode_nets) + 1)
              for ext in ("json", "npz") if ext in formats]
    names += [f"{name}_mode{k}.{ext}" for k in animated_modes(result) if k != 1
              for ext in ("gif", "mp4") if ext in formats]
    return names


def animated_modes(result: RunResult) -> tuple[int, ...]:
    """``output.animate_modes`` (mode numbers from 1), mode 1 when not given."""
    return tuple(result.scenario.output.animate_modes or (1,))


def mode_frames(result: RunResult, k: int) -> Any:
    """Control nets of mode ``k`` (from 1) over one period: ``P_rest + sin(2π φ) D_k`` at the
    phases ``φ`` of the frames (the frames of a modes solve are those of mode 1)."""
    phase = np.asarray(result.times, dtype=float)
    return result.rest_net + np.sin(2.0 * np.pi * phase)[:, None, None, None] \
        * result.mode_nets[k - 1]
