"""A shell body's stresses in its outputs: per face what a single shell run writes.

Each face ``k`` of a Kirchhoff–Love shell body (``physics = "shell"``) is read as one
shell by :mod:`splinedeform.export.shell_fields` (:class:`FaceShell`: its surface, the
body's material, :func:`splinedeform.physics.shell_stress.stresses` of its displacement
net ``P_f − P_rest``), so that

* the ParaView series carries ``membrane_force``, ``bending_moment``, ``von_mises_*`` and
  ``normal_displacement`` on the welded body mesh (:func:`body_stress_fields`);
* ``report.json`` has ``stresses`` per face (``"face k"``: maxima over the frames on the
  face's output grid and the frame where its von Mises peaks), ``probe stresses`` at every
  probe on its face, and for modes the largest von Mises of each mass-normalised mode over
  the body (:func:`body_stress_report`, :func:`body_mode_maxima`);
* ``stresses.png`` draws every face at the frame where von Mises peaks over the body
  (:func:`render_body_stresses`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from .export.shell_fields import frame_chunks, mode_maxima, stress_fields, stress_report

Array = NDArray[np.float64]


class FaceShell:
    """Patch ``patch`` of a shell body's model read as one shell (``surface``,
    ``stresses``), as :mod:`splinedeform.export.shell_fields` reads a single shell."""

    physics = "shell"

    def __init__(self, model: Any, patch: int) -> None:
        self.surface = model.patches[patch]
        self.material = model.material

    def stresses(self, displacement: Any, u: Any, v: Any, at_poles: str = "raise") -> Any:
        """:func:`splinedeform.physics.shell_stress.stresses` of this face."""
        from .physics.shell_stress import stresses

        return stresses(self.surface, self.material, displacement, u, v, at_poles)


def face_shells(model: Any) -> list[FaceShell]:
    """One :class:`FaceShell` per patch of a shell body's model."""
    return [FaceShell(model, k) for k in range(len(model.patches))]


def body_stress_fields(model: Any, rests: Sequence[Array], nets: Sequence[Array],
                       resolution: int) -> Callable[[int], dict[str, Array]]:
    """Point data of frame ``f`` on the patches' output grids side by side (patch after
    patch, each row-major), for :func:`splinedeform.export.body.write_body_series`."""
    per_face = [stress_fields(face, rest, net, resolution)
                for face, rest, net in zip(face_shells(model), rests, nets)]

    def fields(f: int) -> dict[str, Array]:
        parts = [face(f) for face in per_face]
        return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}
    return fields


def frame_peaks(model: Any, rests: Sequence[Array], nets: Sequence[Array], resolution: int
                ) -> Array:
    """Largest von Mises stress (any layer) over the body in every frame ``(F,)``."""
    peaks = np.zeros(len(nets[0]))
    for face, rest, net in zip(face_shells(model), rests, nets):
        for first, chunk in frame_chunks(face, rest, net, resolution):
            top = np.max([np.nan_to_num(s, nan=0.0).reshape(len(chunk.N), -1).max(axis=1)
                          for s in chunk.von_mises.values()], axis=0)
            peaks[first:first + top.size] = np.maximum(peaks[first:first + top.size], top)
    return peaks


def body_stress_report(model: Any, faces: Sequence[int], rests: Sequence[Array],
                       times: Array, nets: Sequence[Array], resolution: int,
                       probe_points: dict[str, tuple[float, float]],
                       probe_patches: dict[str, int], frame_label: str) -> dict[str, Any]:
    """The report's ``stresses`` (per face) and ``probe stresses`` (module docstring)."""
    out: dict[str, Any] = {"stresses": {}, "probe stresses": {frame_label: np.asarray(times)}}
    for k, (face, rest, net) in enumerate(zip(face_shells(model), rests, nets)):
        mine = {name: at for name, at in probe_points.items() if probe_patches[name] == k}
        part = stress_report(face, rest, times, net, resolution, mine, frame_label)
        out["stresses"][f"face {faces[k]}"] = part["stresses"]
        out["probe stresses"].update(part["probe stresses"])
    return out


def body_mode_maxima(model: Any, shapes: Sequence[Array], resolution: int
                     ) -> dict[str, Array]:
    """Largest von Mises stress (top, bottom) of each mass-normalised mode over the body,
    from the modes' per-patch shapes ``(k, n_u, n_v, 3)``."""
    parts = [mode_maxima(face, phi, resolution) for face, phi in zip(face_shells(model), shapes)]
    return {key: np.max([p[key] for p in parts], axis=0) for key in parts[0]}


def render_body_stresses(path: Path, model: Any, rests: Sequence[Array],
                         nets: Sequence[Array], title: str, resolution: int) -> Path:
    """``stresses.png`` of a shell body in the state ``nets`` (one net per patch): every
    face on its output mesh (a trimmed face's clipped to its region), coloured by von Mises top and bottom on one scale
    (:func:`splinedeform.viz.stresses.stress_figure`)."""
    from .export.frames import tessellate_frames
    from .export.shell_fields import output_parameters
    from .viz.figures import _save_png
    from .viz.stresses import stress_figure

    points, triangles, layers, offset = [], [], {"top": [], "bottom": []}, 0
    for face, rest, net in zip(face_shells(model), rests, nets):
        U, V = output_parameters(face.surface, resolution)    # a trimmed face: its region
        s = face.stresses(np.asarray(net, dtype=float) - rest, U, V, at_poles="nan")
        X, F = tessellate_frames(face.surface, np.asarray(net, dtype=float), resolution)
        points.append(X)
        triangles.append(F + offset)
        offset += len(X)
        for layer in layers:
            layers[layer].append(s.von_mises[layer].ravel())
    fields = {f"{layer} face": np.concatenate(v) for layer, v in layers.items()}
    return _save_png(stress_figure(np.concatenate(points), np.concatenate(triangles), fields,
                                   title), path)
