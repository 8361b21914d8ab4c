"""Measures of a run shared by a single surface (:mod:`splinedeform.pipeline`) and a body
(:mod:`splinedeform.pipeline_body`): the largest displacement per frame and the energies."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .pipeline import RunResult


def displacement_per_frame(surface: Any, D: Any, resolution: int) -> Any:
    """``max_(u,v) |d_f(u, v)|`` per frame on the output grid of ``surface``, for net
    displacements ``D (F, n_u, n_v, 3)`` (inside the trim loops of a trimmed surface)."""
    import numpy as np

    from .rational import grid_nets

    if surface.trim is not None:             # the displacement inside the trim loops only
        from .export import tessellate_frames

        grid = tessellate_frames(surface, D, resolution)[0]
    else:
        uu, vv = surface.sample_parameters(resolution)
        grid = grid_nets(surface, uu, vv, D)
    # |d| per frame, scaled so that the squares of a tiny d do not underflow
    size = float(np.abs(grid).max(initial=0.0))
    scale = size if 0.0 < size < np.inf else 1.0
    return scale * np.linalg.norm(grid / scale, axis=-1).reshape(len(grid), -1).max(axis=1)


def energies(result: RunResult) -> dict[str, Any] | None:
    """The energies of a run: per frame for a dynamic solve, of the equilibrium for a
    static one, None for modes."""
    solution, kind = result.solution, result.scenario.solve.kind
    if kind == "dynamic":
        energy = solution.energy(result.times)
        return {"time": result.times, "kinetic": energy.kinetic, "strain": energy.strain,
                "work": energy.work, "total": energy.total}
    if kind == "static":
        energy = solution.energy()
        return {"strain": float(energy.strain), "work": float(energy.work),
                "total": float(energy.total)}
    return None
