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
    (module docstring; the shell removes its free rigid motions itself)."""
    constraints = getattr(model, "constraints", None)
    if constraints is None or not constraints.unconstrained or model.rigid_modes != 1:
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
    from .pipeline import RunResult, _net_normals, solve_and_modes

    solve = scenario.solve
    times = np.asarray(solve.frame_times() if solve.kind == "dynamic"
                       else np.linspace(0.0, 1.0, solve.frames))
    solution, omegas, shapes = solve_and_modes(scenario, built, stages, times, body_static)
    patches = built.surface.patches
    mode_nets = None if shapes is None else body_mode_displacements(
        patches, shapes, getattr(built.surface, "orientation", ()))
    with stages.stage("frames"), _located(scenario, "solve"):
        nets = _frames(scenario, patches, solution, times, mode_nets)
    shell_modes = None
    if shapes is not None and shapes[0].ndim == 4:     # the shell's modes move x, y, z
        shell_modes = shapes
        shapes = [np.einsum("kabc,abc->kab", phi, _net_normals(s))
                  for phi, s in zip(shapes, patches)]
    result = RunResult(scenario=scenario, built=built, solution=solution, times=times,
                       nets=nets, omegas=omegas, mode_shapes=shapes, mode_nets=mode_nets,
                       shell_modes=shell_modes)
    _measure(result)
    return result


def body_mode_displacements(patches: Any, shapes: list[Any],
                            orientation: Any = ()) -> list[Any]:
    """Per patch the modes as net displacements, scaled over the whole body.

    A scalar mode ``φ_k`` moves each control point along ``n̄``, the outward unit net normal
    (:func:`splinedeform.pipeline._net_normals` turned by the face's ``orientation``)
    averaged over every control point of the body that coincides with it at rest:
    ``D_k = φ_k n̄``. The control points merged across a shared edge, a seam or at a pole
    have one ``φ_k`` and one ``n̄``, so the drawn mode keeps the body closed. A shell's
    modes ``(k, n_u, n_v, 3)`` are displacements already.
    """
    normals = body_net_normals(patches, orientation)
    D = [phi if phi.ndim == 4 else phi[..., None] * n[None]
         for phi, n in zip(shapes, normals)]
    rest = np.concatenate([s.control_points.reshape(-1, 3) for s in patches])
    size = float(np.ptp(rest, axis=0).max()) or 1.0
    peak = np.max([np.linalg.norm(d, axis=-1).max(axis=(1, 2)) for d in D], axis=0)
    factor = 0.1 * size / np.where(peak > 0, peak, 1.0)
    return [d * factor[:, None, None, None] for d in D]


def body_net_normals(patches: Any, orientation: Any = ()) -> list[Any]:
    """Per patch ``(n_u, n_v, 3)``: ``n̄`` of :func:`body_mode_displacements`, the sum of
    the outward net normals ``σ_p n_p`` over the control points that coincide at rest (to
    1e-9 of the body's size, or 1e-9 below a size of 1), normalised; a point whose sum
    vanishes keeps its own."""
    from .pipeline import _net_normals
    from .viz.plots import _mean_per_point

    signs = list(orientation) or [1] * len(patches)
    own = [sign * _net_normals(s) for s, sign in zip(patches, signs)]
    rest = np.concatenate([s.control_points.reshape(-1, 3) for s in patches])
    flat = np.concatenate([n.reshape(-1, 3) for n in own])
    total = _mean_per_point(rest, flat)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    mean = np.where(length > 1e-9, total / np.where(length > 1e-9, length, 1.0), flat)
    sizes = np.cumsum([0] + [s.shape[0] * s.shape[1] for s in patches])
    return [mean[a:b].reshape(n.shape) for a, b, n in zip(sizes[:-1], sizes[1:], own)]


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


def body_readout(model: Any) -> Any:
    """The :class:`~splinedeform.readout.BodyReadout` of a body's model (a plate body's
    own, or the shell body's patches, map and reduced matrices)."""
    from .readout import BodyReadout

    readout = getattr(model, "readout", None)
    if isinstance(readout, BodyReadout):
        return readout
    M, _, K = model.matrices()
    return BodyReadout(tuple(model.patches), model.T, M, K)


def _measure(result: Any) -> None:
    """The probes' displacements per frame (:mod:`splinedeform.probes_body`: each face's
    centre unless ``output.probes`` names points), the largest displacement on the patches'
    output grids per frame, and the energies."""
    from .probes_body import body_probes
    from .run_measures import displacement_per_frame, energies

    scenario, body = result.scenario, result.built.surface
    readout = body_readout(result.built.model)
    with _located(scenario, "output.probes"):
        probes = body_probes(scenario, body)
    for probe in probes:
        result.probes[probe.name] = readout.probe(result.nets, probe.patch, *probe.at)
        result.probe_points[probe.name] = probe.at
        result.probe_patches[probe.name] = probe.patch
    per_frame = np.zeros(len(result.times))
    for surface, nets in zip(body.patches, result.nets):
        per_frame = np.maximum(per_frame, displacement_per_frame(
            surface, nets - surface.control_points, scenario.output.resolution))
    result.displacement_per_frame = per_frame
    result.max_displacement = float(per_frame.max(initial=0.0))
    result.energy = energies(result)
