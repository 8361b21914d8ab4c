"""A shell run's stresses in its outputs: ParaView point data, probes and report maxima.

For a Kirchhoff–Love shell (``physics = "shell"``) every frame's displacement net
``P_f − P_rest`` is turned into stresses (:mod:`splinedeform.physics.shell_stress`) on the
output grid ``surface.sample_parameters(resolution)`` and at the probes. Points where the
surface degenerates (a pole) carry NaN; maxima skip them.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def is_shell(model: Any) -> bool:
    """Whether the run's model is the Kirchhoff–Love shell (it has stresses)."""
    return getattr(model, "physics", None) == "shell" and hasattr(model, "stresses")


#: frames × grid points evaluated at once (bounds the work arrays to some 10⁷ floats)
CHUNK_POINTS = 200_000


def output_parameters(surface: Any, resolution: int) -> tuple[Array, Array]:
    """``(U, V)`` of the output mesh's points, in its order: the grid
    ``surface.sample_parameters(resolution)`` ``(r_u, r_v)``, or on a trimmed surface the
    points of that grid clipped to its trim loops ``(N, 1)``
    (:func:`splinedeform.trim.tessellate.surface_grid`, as the meshes are)."""
    u, v = surface.sample_parameters(int(resolution))
    if getattr(surface, "trim", None) is not None:
        from ..trim.tessellate import surface_grid

        points = surface_grid(surface, u, v)[0]
        return points[:, :1], points[:, 1:]
    return tuple(np.meshgrid(u, v, indexing="ij"))  # type: ignore[return-value]


def grid_stresses(model: Any, rest: Array, nets: Array, resolution: int) -> Any:
    """:class:`~splinedeform.physics.shell_stress.ShellStresses` of frames ``(F, n_u, n_v, 3)``
    on the output mesh's points (:func:`output_parameters`), fields ``(F, r_u, r_v, ...)``
    (``(F, N, 1, ...)`` on a trimmed surface)."""
    U, V = output_parameters(model.surface, resolution)
    return model.stresses(np.asarray(nets) - rest, U, V, at_poles="nan")


def frame_chunks(model: Any, rest: Array, nets: Array, resolution: int) -> Any:
    """``(first frame, ShellStresses of a chunk of frames)`` over all frames, in order."""
    U, _ = output_parameters(model.surface, resolution)
    step = max(1, CHUNK_POINTS // U.size)
    for f in range(0, len(nets), step):
        yield f, grid_stresses(model, rest, nets[f:f + step], resolution)


def stress_fields(model: Any, rest: Array, nets: Array, resolution: int
                  ) -> Callable[[int], dict[str, Array]]:
    """Point data of frame ``f`` on the row-major output grid (for the ParaView series).

    ``membrane_force`` ``(N_11, N_22, N_12)`` and ``bending_moment`` ``(M_11, M_22, M_12)``
    in the local frame, ``von_mises_top``, ``_middle``, ``_bottom`` and
    ``normal_displacement``. Frames are evaluated a chunk at a time, in the order asked.
    """
    chunks = frame_chunks(model, rest, nets, resolution)
    held: list[Any] = [-1, None]

    def fields(f: int) -> dict[str, Array]:
        while not (0 <= f - held[0] < len(held[1].N) if held[1] is not None else False):
            held[:] = next(chunks)
        return held[1].select(f - held[0]).point_data()
    return fields


def peak_stress_frame(model: Any, rest: Array, nets: Array, resolution: int) -> int:
    """Index of the frame with the largest von Mises stress on the output grid (first such)."""
    best = (-1.0, 0)
    for first, chunk in frame_chunks(model, rest, nets, resolution):
        peaks = np.max([np.nan_to_num(s, nan=0.0).reshape(len(chunk.N), -1).max(axis=1)
                        for s in chunk.von_mises.values()], axis=0)
        f = int(np.argmax(peaks))
        best = max(best, (float(peaks[f]), -(first + f)))
    return -best[1]


def stress_report(model: Any, rest: Array, times: Array, nets: Array, resolution: int,
                  probe_points: dict[str, tuple[float, float]], frame_label: str
                  ) -> dict[str, Any]:
    """The report's sections ``stresses`` (maxima over all frames on the output grid and
    the frame where von Mises peaks) and ``probe stresses`` (von Mises, ``N`` and ``M`` at
    each probe, per frame)."""
    maxima: dict[str, float] = {}
    peak = (-1.0, 0)
    for first, chunk in frame_chunks(model, rest, nets, resolution):
        for f in range(len(chunk.N)):
            frame = chunk.select(f).maxima()
            for key, value in frame.items():
                maxima[key] = max(maxima.get(key, 0.0), value)
            vm = max(frame[f"max von Mises {layer}"] for layer in ("top", "middle", "bottom"))
            peak = max(peak, (vm, -(first + f)))
    probes: dict[str, Any] = {frame_label: np.asarray(times)}
    for name, (u, v) in probe_points.items():
        s = model.stresses(np.asarray(nets) - rest, u, v, at_poles="nan")
        probes.update({f"{name} von Mises top": s.von_mises["top"],
                       f"{name} von Mises bottom": s.von_mises["bottom"],
                       **{f"{name} N{ij}": s.N[:, k] for k, ij in enumerate(("11", "22", "12"))},
                       **{f"{name} M{ij}": s.M[:, k] for k, ij in enumerate(("11", "22", "12"))}})
    return {"stresses": {**maxima, f"{frame_label} of the largest von Mises":
                         float(np.asarray(times)[-peak[1]])},
            "probe stresses": probes}


def mode_maxima(model: Any, shapes: Array, resolution: int) -> dict[str, Array]:
    """Largest von Mises stress (top, bottom) of each mass-normalised mode shape
    ``(k, n_u, n_v, 3)``."""
    out: dict[str, list[float]] = {"max von Mises top": [], "max von Mises bottom": []}
    zero = np.zeros(model.surface.shape + (3,))
    for first, chunk in frame_chunks(model, zero, shapes, resolution):
        for f in range(len(chunk.N)):
            m = chunk.select(f).maxima()
            out["max von Mises top"].append(m["max von Mises top"])
            out["max von Mises bottom"].append(m["max von Mises bottom"])
    return {f"{key} (mass-normalised shape)": np.asarray(v) for key, v in out.items()}
