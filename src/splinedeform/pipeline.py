"""Running a scenario: build, solve, sample frames, write every requested output.

The scenario reader (:mod:`splinedeform.scenario`) validates and builds; this module is the
pipeline the command line calls: ``run(scenario, outdir, progress) -> RunResult``.
"""

from __future__ import annotations

import importlib.util
import time
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

from .budget import Budget, check as check_budget
from .errors import InputError
from .scenario import Built, Scenario, SolveSpec, _located, build, scenario_to_toml

#: ``progress(stage, done, total)``, called as each stage advances
ProgressCallback = Callable[[str, int, int], None]


@dataclass
class RunResult:
    """Everything a run produced; the command line prints :func:`summary_rows` of it.

    ``times``/``nets`` are the frames: physical times for a dynamic solve, the load factor
    ``λ ∈ [0, 1]`` of the (linear) static response ``λ d`` for a static one, and the phase
    (in periods) of the lowest mode for a modes solve.
    """

    scenario: Scenario
    built: Built
    solution: Any
    times: Any
    nets: Any
    omegas: Any = None
    mode_shapes: Any = None
    probes: dict[str, Any] = field(default_factory=dict)
    probe_points: dict[str, tuple[float, float]] = field(default_factory=dict)
    energy: dict[str, Any] | None = None
    max_displacement: float = 0.0
    timings: dict[str, float] = field(default_factory=dict)
    outputs: list[tuple[str, Path]] = field(default_factory=list)
    report: dict[str, Any] = field(default_factory=dict)

    @property
    def n_free(self) -> int:
        return int(self.built.model.n_free)

    @property
    def rest_net(self) -> Any:
        return self.built.surface.control_points


class _Stages:
    """Times each stage and forwards progress to the callback."""

    def __init__(self, progress: ProgressCallback | None) -> None:
        self.progress = progress
        self.timings: dict[str, float] = {}

    def tick(self, stage: str, done: int, total: int) -> None:
        if self.progress is not None:
            self.progress(stage, done, total)

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        self.tick(name, 0, 1)
        start = time.perf_counter()
        yield
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - start
        self.tick(name, 1, 1)


def run(scenario: Scenario, outdir: str | Path | None = None,
        progress: ProgressCallback | None = None, budget: Budget | None = None) -> RunResult:
    """Build, solve, sample the frames and write every requested output to ``outdir``.

    Parameters
    ----------
    scenario : Scenario
    outdir : path, optional
        Output folder, created if missing; required when the scenario asks for outputs.
    progress : callable, optional
        ``progress(stage, done, total)`` for the stages ``build``, ``solve``, ``modes``,
        ``frames`` and one per output.
    budget : Budget, optional
        Limits of memory, disk, files and work (default :class:`~splinedeform.budget.Budget`):
        a run estimated beyond them is refused after building, before solving.
    """
    stages = _Stages(progress)
    formats = scenario.output.formats
    folder = _prepare_outdir(scenario, outdir) if formats else None
    with stages.stage("build"):
        built = build(scenario)
        check_budget(scenario, built.model, budget)
    result = _solve(scenario, built, stages)
    result.timings = stages.timings
    if folder is not None:
        _write_outputs(result, folder, stages)
    result.timings = dict(stages.timings)
    return result


def _prepare_outdir(scenario: Scenario, outdir: str | Path | None) -> Path:
    if outdir is None:
        raise InputError("this scenario writes outputs (output.formats = "
                         f"{list(scenario.output.formats)}); give an output folder")
    if "3dm" in scenario.output.formats and importlib.util.find_spec("rhino3dm") is None:
        raise scenario.error("output.formats", "3dm needs the 'cad' extra (rhino3dm): "
                                               "pip install 'splinedeform[cad]'")
    if "mp4" in scenario.output.formats:
        from .viz import mp4_available

        if not mp4_available():
            raise scenario.error("output.formats", "mp4 needs an ffmpeg encoder: install the "
                                                   "extra `video` (imageio-ffmpeg) or use gif")
    folder = Path(outdir)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the output folder {folder}: {exc}") from None
    return folder


def _solve(scenario: Scenario, built: Built, stages: _Stages) -> RunResult:
    import numpy as np

    solve, model = scenario.solve, built.model
    solution, omegas, shapes = None, None, None
    times = np.asarray(solve.frame_times() if solve.kind == "dynamic"
                       else np.linspace(0.0, 1.0, solve.frames))
    with stages.stage("solve"), _located(scenario, "solve"):
        if solve.kind == "static":
            solution = model.static(built.load)
        elif solve.kind == "dynamic":
            solution = model.dynamic(built.load, solve.t_end, method=solve.method,
                                     **_method_options(solve, times, scenario.output.time))
    if solve.modes > 0 and solve.kind != "static":
        with stages.stage("modes"), _located(scenario, "solve.modes"):
            omegas, shapes = model.modes(min(solve.modes, model.n_free))
    with stages.stage("frames"), _located(scenario, "solve"):
        nets = _frames(scenario, built, solution, times, shapes)
    result = RunResult(scenario=scenario, built=built, solution=solution, times=times,
                       nets=nets, omegas=omegas, mode_shapes=shapes)
    with np.errstate(over="ignore", invalid="ignore"):
        _measure(result)
    _require_finite(result)
    return result


def _extreme_inputs(scenario: Scenario) -> list[tuple[str, float]]:
    """Numeric inputs of extreme magnitude (``|x| > 1e100`` or ``0 < |x| < 1e-100``) by key path."""
    import math

    values: list[tuple[str, Any]] = [(f"material.{name}", getattr(scenario.material, name))
                                     for name in ("mass", "damping", "rayleigh", "w10", "w01",
                                                  "w20", "w11", "w02")]
    for i, spec in enumerate(scenario.loads, start=1):
        values.append((f"load[{i}].q", spec.q))
        values.append((f"load[{i}].omega", spec.omega))
        values.extend((f"load[{i}].force[{j}]", f) for j, f in enumerate(spec.force or (), start=1))
    extreme = []
    for path, value in values:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            size = abs(float(value))
            if not math.isfinite(size) or size > 1e100 or 0.0 < size < 1e-100:
                extreme.append((path, float(value)))
    return extreme


def _require_finite(result: RunResult) -> None:
    """Refuse a solution, energy or probe that overflowed to NaN or inf before anything is written."""
    import numpy as np

    arrays = [result.nets, result.max_displacement, *result.probes.values(),
              *(result.energy or {}).values()]
    if result.omegas is not None:
        arrays.append(result.omegas)
    if all(np.all(np.isfinite(np.asarray(a, dtype=float))) for a in arrays):
        return
    scenario = result.scenario
    extreme = _extreme_inputs(scenario)
    if extreme:
        path = extreme[0][0]
        named = ", ".join(f"{key} = {value:g}" for key, value in extreme)
        cause = f"inputs of extreme magnitude made it so: {named}; bring them to a scale " \
                "where the products of force, mass, damping and stiffness stay below ~1e300"
    else:
        path, cause = "solve", "no single input is extreme; the combination of scales overflows"
    raise scenario.error(path, "the solution is not finite (NaN or inf) and nothing was "
                         f"written: {cause}")


def _method_options(solve: SolveSpec, times: Any, mesh_time: float | None) -> dict[str, Any]:
    import numpy as np

    if solve.method == "analytic":
        return {"function_samples": solve.function_samples}
    extra = [] if mesh_time is None else [mesh_time]
    options: dict[str, Any] = {"times": np.union1d(times, extra)}
    if solve.method in ("newmark", "genalpha"):
        frames = max(len(times) - 1, 1)
        options["dt"] = solve.dt if solve.dt is not None else solve.t_end / (20 * frames)
    elif solve.method.startswith("radau") and solve.method != "radau":
        options["dt"] = solve.dt                 # None: one Radau IIA step per frame
    else:
        options.update(rtol=solve.rtol, atol=solve.atol)
    return options


def _frames(scenario: Scenario, built: Built, solution: Any, times: Any, shapes: Any) -> Any:
    """Control nets ``(F, n_u, n_v, 3)`` at the frame times (see :class:`RunResult`)."""
    import numpy as np

    rest = built.surface.control_points
    kind = scenario.solve.kind
    if kind == "dynamic":
        return np.asarray(solution.control_points(times))
    if kind == "static":
        d = solution.control_points() - rest
        return rest + times[:, None, None, None] * d
    direction = _net_normals(built.surface)
    size = float(np.ptp(rest.reshape(-1, 3), axis=0).max()) or 1.0
    peak = float(np.abs(shapes[0]).max()) or 1.0
    amplitude = 0.1 * size / peak
    wave = np.sin(2.0 * np.pi * times)
    return rest + amplitude * wave[:, None, None, None] * (shapes[0][..., None] * direction)


def _net_normals(surface: Any) -> Any:
    """Unit normals at the Greville points (nudged off degenerate edges such as poles)."""
    import numpy as np

    def nudged(basis: Any) -> Any:
        eps = 1e-3 * basis.length
        return np.clip(basis.greville(), eps, basis.length - eps)
    u, v = nudged(surface.basis_u), nudged(surface.basis_v)
    xu = surface.evaluate_grid(u, v, du=1)
    xv = surface.evaluate_grid(u, v, dv=1)
    n = np.cross(xu, xv)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    return np.where(length > 0, n / np.where(length > 0, length, 1.0), [0.0, 0.0, 1.0])


def _measure(result: RunResult) -> None:
    """Probe histories, the largest surface displacement and the energies."""
    import numpy as np

    scenario, surface = result.scenario, result.built.surface
    D = result.nets - surface.control_points
    probes = scenario.output.probes or (_domain_centre(surface),)
    for i, (u, v) in enumerate(probes, start=1):
        E = surface.evaluation_matrix([u], [v]).toarray()[0].reshape(surface.shape)
        name = f"p{i} ({u:g}, {v:g})"
        result.probes[name] = np.einsum("kl,fklc->fc", E, D)
        result.probe_points[name] = (float(u), float(v))
    uu, vv = surface.sample_parameters(scenario.output.resolution)
    Bu = surface.basis_u.matrix(uu).toarray()
    Bv = surface.basis_v.matrix(vv).toarray()
    grid = np.einsum("ik,fklc,jl->fijc", Bu, D, Bv, optimize=True)
    result.max_displacement = float(np.linalg.norm(grid, axis=-1).max())
    solution = result.solution
    if scenario.solve.kind == "dynamic":
        energy = solution.energy(result.times)
        result.energy = {"time": result.times, "kinetic": energy.kinetic,
                         "strain": energy.strain, "work": energy.work, "total": energy.total}
    elif scenario.solve.kind == "static":
        energy = solution.energy()
        result.energy = {"strain": float(energy.strain), "work": float(energy.work),
                         "total": float(energy.total)}


def _domain_centre(surface: Any) -> tuple[float, float]:
    (_, lu), (_, lv) = surface.domain
    return (0.5 * lu, 0.5 * lv)


# -- outputs ---------------------------------------------------------------------------
def _mesh_net(result: RunResult) -> Any:
    """The control net written as OBJ/STL/PLY: ``output.time``, else the last frame."""
    time_ = result.scenario.output.time
    if time_ is not None:
        return result.solution.control_points(time_)
    return result.nets[-1]


def _write_outputs(result: RunResult, folder: Path, stages: _Stages) -> None:
    from . import export

    scenario = result.scenario
    formats, name, res = scenario.output.formats, scenario.name, scenario.output.resolution
    surface, rest = result.built.surface, result.rest_net
    times, nets = result.times, result.nets
    for ext in ("obj", "stl", "ply"):
        if ext in formats:
            with stages.stage(f"mesh .{ext}"):
                net = _mesh_net(result)
                vertices, faces = surface.tessellate(res, control_points=net)
                d = vertices - surface.tessellate(res)[0]
                import numpy as np
                data = {"displacement": d, "displacement_magnitude": np.linalg.norm(d, axis=1)}
                result.outputs.append((f"mesh .{ext}", export.write_mesh(
                    folder / f"{name}.{ext}", vertices, faces, point_data=data)))
    if "vtu" in formats:
        with stages.stage("time series"):
            result.outputs.append(("time series .pvd", export.write_time_series(
                folder, name, surface, rest, times, nets, resolution=res)))
    if "json" in formats or "npz" in formats:
        with stages.stage("control nets"):
            wanted = [ext for ext in export.CONTROL_NET_FORMATS if ext in formats]
            for path in export.write_control_nets(folder, f"{name}_nets", surface, times, nets,
                                                  formats=wanted):
                result.outputs.append((f"control nets {path.suffix}", path))
    if "3dm" in formats:
        from .cad import write_frames_3dm

        with stages.stage("CAD surfaces"):
            label = {"dynamic": "time", "static": "load factor",
                     "modes": "phase"}[scenario.solve.kind]
            result.outputs.append(("NURBS surfaces .3dm", write_frames_3dm(
                folder / f"{name}.3dm", surface, times, nets, label)))
    if "images" in formats:
        _write_images(result, folder, stages)
    for ext in ("gif", "mp4"):
        if ext in formats:
            _write_animation(result, folder / f"{name}.{ext}", stages)
    if "viewer" in formats:
        from .viz import write_viewer

        with stages.stage("viewer"):
            result.outputs.append(("viewer", write_viewer(folder / "viewer.html", surface, rest,
                                                          times, nets, resolution=res)))
    if "report" in formats:
        with stages.stage("report"):
            result.report = make_report(result)
            paths = export.write_report(folder, result.report)
            result.outputs += [("report .json", paths[0]), ("report .md", paths[1])]


def _write_images(result: RunResult, folder: Path, stages: _Stages) -> None:
    from . import viz

    surface, rest = result.built.surface, result.rest_net
    kind = result.scenario.solve.kind
    with stages.stage("images"):
        label = {"dynamic": "t", "static": "load factor", "modes": "phase"}[kind]
        last = result.nets[-1] if kind != "modes" else result.nets[len(result.nets) // 4]
        last_t = result.times[-1] if kind != "modes" else result.times[len(result.times) // 4]
        result.outputs.append(("picture", viz.render_surfaces(
            folder / "surfaces.png", surface, rest, [result.nets[0], last],
            [f"initial ({label} = {result.times[0]:g})", f"{label} = {last_t:.4g}"])))
        if kind == "dynamic":
            result.outputs.append(("probe plot", viz.plot_probes(
                folder / "probes.png", result.times, result.probes)))
        if result.omegas is not None:
            result.outputs.append(("mode shapes", viz.plot_modes(
                folder / "modes.png", surface, result.omegas, result.mode_shapes)))


def _write_animation(result: RunResult, path: Path, stages: _Stages) -> None:
    from .viz import write_animation

    stage = f"animation {path.suffix}"
    with stages.stage(stage):
        result.outputs.append((stage, write_animation(
            path, result.built.surface, result.rest_net, result.times, result.nets,
            resolution=result.scenario.output.resolution,
            progress=lambda done, total: stages.tick(stage, done, total + 1))))


def make_report(result: RunResult) -> dict[str, Any]:
    """The content of ``report.json`` / ``report.md``: inputs, solver, timings, energies, probes."""
    import numpy as np

    s, surface = result.scenario, result.built.surface
    report: dict[str, Any] = {
        "inputs": {"source": s.source, **tomllib.loads(scenario_to_toml(s))},
        "surface": {"shape": s.surface.shape, "net": f"{surface.shape[0]} x {surface.shape[1]}",
                    "degree": [surface.basis_u.degree, surface.basis_v.degree],
                    "knots": [surface.basis_u.kind, surface.basis_v.kind],
                    "domain": [list(d) for d in surface.domain],
                    "fit_error": surface.fit_error,
                    "free control points": result.n_free},
        "solver": {"kind": s.solve.kind,
                   "method": s.solve.method if s.solve.kind == "dynamic" else "direct",
                   "t_end": s.solve.t_end if s.solve.kind == "dynamic" else None,
                   "frames": len(result.times),
                   "max displacement": result.max_displacement},
        "timings": {**_solution_timings(result), **result.timings},
    }
    if result.omegas is not None:
        report["modes"] = {"mode": list(range(1, len(result.omegas) + 1)),
                           "omega": result.omegas,
                           "frequency (omega / 2 pi)": np.asarray(result.omegas) / (2 * np.pi)}
    if result.energy is not None:
        report["energies"] = result.energy
    frame_label = {"dynamic": "time", "static": "load factor", "modes": "phase"}[s.solve.kind]
    probes: dict[str, Any] = {frame_label: result.times}
    for name, d in result.probes.items():
        probes.update({f"{name} d{c}": d[:, i] for i, c in enumerate("xyz")})
        probes[f"{name} magnitude"] = np.linalg.norm(d, axis=1)
    report["probes"] = probes
    return report


def _solution_timings(result: RunResult) -> dict[str, float]:
    timings = getattr(result.solution, "timings", None) or {}
    return {f"solver: {k}": float(v) for k, v in timings.items()}


def summary_rows(result: RunResult) -> list[tuple[str, str]]:
    """(label, value) rows of the closing summary: sizes, times per stage, outputs."""
    s, surface = result.scenario, result.built.surface
    rows = [("scenario", s.title or s.name),
            ("control net", f"{surface.shape[0]} x {surface.shape[1]} "
                            f"({surface.shape[0] * surface.shape[1]} points)"),
            ("free control points", str(result.n_free)),
            ("solve", s.solve.kind + (f" ({s.solve.method})" if s.solve.kind == "dynamic"
                                      else "")),
            ("modes", "-" if result.omegas is None else
             f"{len(result.omegas)} (lowest ω = {float(result.omegas[0]):.5g})"),
            ("frames", str(len(result.times))),
            ("max displacement", f"{result.max_displacement:.6g}")]
    rows += [(f"time: {stage}", f"{seconds:.3f} s") for stage, seconds in result.timings.items()]
    rows += [(label, str(path)) for label, path in result.outputs]
    return rows


