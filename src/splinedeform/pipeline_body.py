"""Solving a body's scenario: static, modes or the closed-form dynamics of all its patches.

The same stages as a single surface (:mod:`splinedeform.pipeline`), on per-patch nets:
``result.nets`` is a list with one ``(F, n_u, n_v, 3)`` array per patch, the modes'
``mode_nets`` one ``(k, n_u, n_v, 3)`` array per patch (each mode moves every control
point along its patch's normal, ``φ_k n``, scaled so that its largest control-point
displacement over the body is 0.1 × the largest side of the body's box).

A body that nothing holds (every boundary edge free, or none at all: a closed box) has
the constant translations as rigid motions. Its static equilibrium under a load without
resultant (a pressure on a closed body) is solved with the body's mean motion held at
zero (:func:`splinedeform.solvers.floating.floating_static`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .scenario import Built, Scenario, _located


def body_static(model: Any, load: Any) -> Any:
    """``model.static(load)``, or for a body that nothing holds the floating equilibrium
    (module docstring)."""
    if not model.constraints.unconstrained or model.rigid_modes != 1:
        return model.static(load)
    import time

    from .loads import as_load
    from .solution import StaticSolution
    from .solvers.floating import floating_static

    start = time.perf_counter()
    F = model.load_vector(as_load(load), 0.0)
    Z = np.ones((model.n_free, 1))               # a constant translation of every point
    M, _, K = model.matrices()
    d = floating_static(K, M, F, Z)
    return StaticSolution(model.readout, d, F, {"static": time.perf_counter() - start})


def solve_body(scenario: Scenario, built: Built, stages: Any) -> Any:
    """The :class:`~splinedeform.pipeline.RunResult` of a body scenario (module docstring)."""
    from .pipeline import RunResult, solve_and_modes

    solve = scenario.solve
    times = np.asarray(solve.frame_times() if solve.kind == "dynamic"
                       else np.linspace(0.0, 1.0, solve.frames))
    solution, omegas, shapes = solve_and_modes(scenario, built, stages, times, body_static)
    patches = built.surface.patches
    mode_nets = None if shapes is None else body_mode_displacements(patches, shapes)
    with stages.stage("frames"), _located(scenario, "solve"):
        nets = _frames(scenario, patches, solution, times, mode_nets)
    result = RunResult(scenario=scenario, built=built, solution=solution, times=times,
                       nets=nets, omegas=omegas, mode_shapes=shapes, mode_nets=mode_nets)
    _measure(result)
    return result


def body_mode_displacements(patches: Any, shapes: list[Any]) -> list[Any]:
    """Per patch the modes as net displacements ``φ_k n`` scaled over the whole body."""
    from .pipeline import _net_normals

    D = [phi[..., None] * _net_normals(s)[None] for s, phi in zip(patches, shapes)]
    rest = np.concatenate([s.control_points.reshape(-1, 3) for s in patches])
    size = float(np.ptp(rest, axis=0).max()) or 1.0
    peak = np.max([np.linalg.norm(d, axis=-1).max(axis=(1, 2)) for d in D], axis=0)
    factor = 0.1 * size / np.where(peak > 0, peak, 1.0)
    return [d * factor[:, None, None, None] for d in D]


def _frames(scenario: Scenario, patches: Any, solution: Any, times: Any, mode_nets: Any
            ) -> list[Any]:
    """Per patch the control nets ``(F, n_u, n_v, 3)`` at the frames."""
    kind = scenario.solve.kind
    rests = [s.control_points for s in patches]
    if kind == "dynamic":
        return [np.asarray(n) for n in solution.control_points(times)]
    if kind == "static":
        return [r + times[:, None, None, None] * (p - r)
                for r, p in zip(rests, solution.control_points())]
    phase = np.sin(2.0 * np.pi * times)[:, None, None, None]
    return [r + phase * m[0] for r, m in zip(rests, mode_nets)]


PROBE_GRID = 33
"""Samples per direction among which a trimmed face's probe is chosen."""


def probe_parameters(surface: Any) -> tuple[float, float, str]:
    """Where a face's probe reads it: the centre of its parameter rectangle, or, for a
    trimmed face whose region does not hold the centre, the sample of a
    :data:`PROBE_GRID` ² grid inside its region nearest to it (``"inside"``)."""
    (_, lu), (_, lv) = surface.domain
    centre = np.array([0.5 * lu, 0.5 * lv])
    if surface.trim is None:
        return float(centre[0]), float(centre[1]), "centre"
    from .trim.surface_trim import region_contains

    if region_contains(surface, centre[None])[0]:
        return float(centre[0]), float(centre[1]), "centre"
    U, V = np.meshgrid(np.linspace(0.0, lu, PROBE_GRID), np.linspace(0.0, lv, PROBE_GRID))
    grid = np.stack([U.ravel(), V.ravel()], axis=1)
    inside = grid[region_contains(surface, grid)]
    best = inside[np.argmin(np.sum((inside - centre) ** 2, axis=1))]
    return float(best[0]), float(best[1]), "inside"


def _measure(result: Any) -> None:
    """Each face's centre displacement per frame (the probes; :func:`probe_parameters`), the largest displacement on
    the patches' output grids per frame, and the energies."""
    from .run_measures import displacement_per_frame, energies

    scenario, body = result.scenario, result.built.surface
    F = len(result.times)
    per_frame = np.zeros(F)
    for k, (surface, nets) in enumerate(zip(body.patches, result.nets)):
        D = nets - surface.control_points
        u, v, where = probe_parameters(surface)
        E = surface.evaluation_matrix(np.array([u]), np.array([v]))
        face = body.faces[k] if hasattr(body, "faces") else k
        name = f"face {face} {where}"
        result.probes[name] = np.asarray(E @ np.moveaxis(D.reshape(F, -1, 3), 0, 1)
                                         .reshape(E.shape[1], F * 3)).reshape(F, 3)
        result.probe_points[name] = (u, v)
        per_frame = np.maximum(per_frame, displacement_per_frame(
            surface, D, scenario.output.resolution))
    result.displacement_per_frame = per_frame
    result.max_displacement = float(per_frame.max(initial=0.0))
    result.energy = energies(result)
