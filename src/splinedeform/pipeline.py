"""Running a scenario: build, solve, sample frames, write every requested output.

The scenario reader (:mod:`splinedeform.scenario`) validates and builds; this module is the
pipeline the command line calls: ``run(scenario, outdir, progress) -> RunResult``.
"""

from __future__ import annotations

import importlib.util
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

from ._progress import reporting_simulated_time
from .budget import Budget, check as check_budget
from .errors import InputError
from .outputs import make_report, planned_outputs, summary_rows, write_outputs
from .load_scale import ScaledSolution, load_scale
from .scenario import Built, Scenario, SolveSpec, _located, build, build_load
from .pipeline_body import solve_body
from .run_measures import displacement_per_frame, energies
from .scenario.body import is_body

#: ``progress(stage, done, total)``, called as each stage advances
ProgressCallback = Callable[[str, int, int], None]


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT); ``str()`` is one line saying where it stopped, what
    it left incomplete and that re-running the same command cleans it up."""


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
    #: each computed mode as a displacement of the control net ``(k, n_u, n_v, 3)``, scaled
    #: as the frames of a modes solve draw it (:func:`mode_displacements`)
    mode_nets: Any = None
    #: the shell's mass-normalised mode shapes ``(k, n_u, n_v, 3)`` (None otherwise)
    shell_modes: Any = None
    probes: dict[str, Any] = field(default_factory=dict)
    probe_points: dict[str, tuple[float, float]] = field(default_factory=dict)
    #: a body's probes: the patch each probe of :attr:`probe_points` lies on
    probe_patches: dict[str, int] = field(default_factory=dict)
    energy: dict[str, Any] | None = None
    max_displacement: float = 0.0
    #: ``max_(u,v) |d_f(u, v)|`` on the output grid at each frame ``f``
    displacement_per_frame: Any = None
    timings: dict[str, float] = field(default_factory=dict)
    outputs: list[tuple[str, Path]] = field(default_factory=list)
    report: dict[str, Any] = field(default_factory=dict)
    #: files of an earlier run of the same scenario removed from the folder, and files
    #: left in place with the reason (see :mod:`splinedeform.export.run_folder`)
    removed: list[Path] = field(default_factory=list)
    kept: list[tuple[Path, str]] = field(default_factory=list)

    @property
    def n_free(self) -> int:
        return int(self.built.model.n_free)

    @property
    def rest_net(self) -> Any:
        """The rest control net (a body's: a list, one per patch)."""
        if is_body(self.built.surface):
            return [s.control_points for s in self.built.surface.patches]
        return self.built.surface.control_points


class _Stages:
    """Times each stage and forwards progress to the callback."""

    def __init__(self, progress: ProgressCallback | None) -> None:
        self.progress = progress
        self.timings: dict[str, float] = {}
        self.current = "start"

    def tick(self, stage: str, done: int, total: int) -> None:
        self.current = stage
        if self.progress is not None:
            self.progress(stage, done, total)

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        self.tick(name, 0, 1)
        start = time.perf_counter()
        yield
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - start
        self.tick(name, 1, 1)

    def simulated(self, name: str) -> Any:
        """A block in which the integrators' simulated time goes to the bar of ``name``
        (when the progress callback draws it: a ``receiver(stage)`` method)."""
        receiver = getattr(self.progress, "receiver", None)
        return reporting_simulated_time(receiver(name) if callable(receiver) else None)


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
    try:
        with stages.stage("build"):
            built = build(scenario)
            check_budget(scenario, built.model, budget)
        if is_body(built.surface):
            result = solve_body(scenario, built, stages)
            _require_finite(result)
        else:
            result = _solve(scenario, built, stages)
        result.timings = stages.timings
        if folder is not None:
            write_outputs(result, folder, stages)
    except KeyboardInterrupt:
        raise RunInterrupted(_interrupted(scenario, folder, stages.current)) from None
    result.timings = dict(stages.timings)
    return result


def _interrupted(scenario: Scenario, folder: Path | None, stage: str) -> str:
    """The line said when Ctrl-C stops a run during ``stage``."""
    from .export.run_folder import incomplete_note

    note = incomplete_note(folder, scenario.name) if folder is not None else None
    if note is not None:
        return (f"interrupted during {stage}: {note}; run the same command again to clean "
                "it up and write the whole set")
    where = f" in {folder}" if folder is not None else ""
    return f"interrupted during {stage}: no output of this run was written{where}"


def _prepare_outdir(scenario: Scenario, outdir: str | Path | None) -> Path:
    if outdir is None:
        raise InputError("this scenario writes outputs (output.formats = "
                         f"{list(scenario.output.formats)}); give an output folder")
    if "3dm" in scenario.output.formats and importlib.util.find_spec("rhino3dm") is None:
        raise scenario.error("output.formats", "3dm needs the 'cad' extra (rhino3dm): "
                                               "pip install 'splinedeform[cad]'")
    step = [f for f in ("step", "iges") if f in scenario.output.formats]
    if step and importlib.util.find_spec("OCP") is None:
        raise scenario.error("output.formats", f"{step[0]} needs the 'cad-step' extra "
                                               "(OpenCASCADE): pip install "
                                               "'splinedeform[cad-step]'")
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

    times = np.asarray(scenario.solve.frame_times() if scenario.solve.kind == "dynamic"
                       else np.linspace(0.0, 1.0, scenario.solve.frames))
    solution, omegas, shapes = solve_and_modes(scenario, built, stages, times)
    mode_nets = None if shapes is None else mode_displacements(built.surface, shapes)
    with stages.stage("frames"), _located(scenario, "solve"):
        nets = _frames(scenario, built, solution, times, mode_nets)
    shell_modes = None
    if shapes is not None and shapes.ndim == 4:     # the shell's modes move x, y, z
        shell_modes = shapes
        shapes = np.einsum("kabc,abc->kab", shapes, _net_normals(built.surface))
    result = RunResult(scenario=scenario, built=built, solution=solution, times=times,
                       nets=nets, omegas=omegas, mode_shapes=shapes, mode_nets=mode_nets,
                       shell_modes=shell_modes)
    with np.errstate(over="ignore", invalid="ignore"):
        _measure(result)
    _require_finite(result)
    return result


def solve_and_modes(scenario: Scenario, built: Built, stages: _Stages, times: Any,
                    static: Callable[[Any, Any], Any] | None = None) -> tuple[Any, Any, Any]:
    """``(solution, omegas, shapes)``: the static or dynamic solution at ``times`` (None
    for modes) and the modes when asked for; ``static(model, load)`` solves a static one
    (default ``model.static(load)``)."""
    solve, model = scenario.solve, built.model
    solution, omegas, shapes = None, None, None
    scale = load_scale(scenario)           # extreme loads solved at order one, then scaled
    with stages.stage("solve"), _located(scenario, "solve"), stages.simulated("solve"):
        load = built.load if scale == 1.0 else build_load(
            scenario, scale, built.surface if is_body(built.surface) else None)
        if solve.kind == "static":
            solution = (static or (lambda m, f: m.static(f)))(model, load)
        elif solve.kind == "dynamic":
            solution = model.dynamic(load, solve.t_end, method=solve.method,
                                     **_method_options(solve, times, scenario.output.time))
        if solution is not None and scale != 1.0:
            solution = ScaledSolution(solution, scale)
    if solve.modes > 0 and solve.kind != "static":
        with stages.stage("modes"), _located(scenario, "solve.modes"):
            omegas, shapes = model.modes(min(solve.modes, model.n_free))
    return solution, omegas, shapes


def _extreme_inputs(scenario: Scenario) -> list[tuple[str, float]]:
    """Numeric inputs of extreme magnitude (``|x| > 1e100`` or ``0 < |x| < 1e-100``) by key path."""
    import math

    values: list[tuple[str, Any]] = [(f"material.{name}", getattr(scenario.material, name))
                                     for name in ("mass", "damping", "rayleigh", "w10", "w01",
                                                  "w20", "w11", "w02", "E", "thickness",
                                                  "density")]
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

    nets = result.nets if isinstance(result.nets, list) else [result.nets]
    arrays = [*nets, result.max_displacement, *result.probes.values(),
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


def mode_displacements(surface: Any, shapes: Any) -> Any:
    """The modes as control-net displacements ``D_k (k, n_u, n_v, 3)``, each scaled so that
    its largest control-point displacement is 0.1 × the largest side of the net's box.

    A scalar mode ``φ_k (n_u, n_v)`` moves along the net's normals (``φ_k n``); a shell
    mode ``(n_u, n_v, 3)`` is a displacement net already.
    """
    import numpy as np

    D = shapes if shapes.ndim == 4 else shapes[..., None] * _net_normals(surface)[None]
    rest = surface.control_points
    size = float(np.ptp(rest.reshape(-1, 3), axis=0).max()) or 1.0
    peak = np.linalg.norm(D, axis=-1).max(axis=(1, 2))
    return D * (0.1 * size / np.where(peak > 0, peak, 1.0))[:, None, None, None]


def _frames(scenario: Scenario, built: Built, solution: Any, times: Any, mode_nets: Any) -> Any:
    """Control nets ``(F, n_u, n_v, 3)`` at the frame times (see :class:`RunResult`)."""
    import numpy as np

    rest = built.surface.control_points
    kind = scenario.solve.kind
    if kind == "dynamic":
        return np.asarray(solution.control_points(times))
    if kind == "static":
        d = solution.control_points() - rest
        return rest + times[:, None, None, None] * d
    # the lowest mode over one period of its phase
    return rest + np.sin(2.0 * np.pi * times)[:, None, None, None] * mode_nets[0]


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
    at = np.asarray(probes, dtype=float)
    E = surface.evaluation_matrix(at[:, 0], at[:, 1])          # (P, n_u n_v), sparse
    F = D.shape[0]
    histories = (E @ np.moveaxis(D.reshape(F, -1, 3), 0, 1).reshape(E.shape[1], F * 3)
                 ).reshape(len(probes), F, 3)
    for i, (u, v) in enumerate(probes, start=1):
        name = f"p{i} ({u:g}, {v:g})"
        result.probes[name] = histories[i - 1]
        result.probe_points[name] = (float(u), float(v))
    per_frame = displacement_per_frame(surface, D, scenario.output.resolution)
    result.displacement_per_frame = per_frame
    result.max_displacement = float(per_frame.max(initial=0.0))
    result.energy = energies(result)


def _domain_centre(surface: Any) -> tuple[float, float]:
    """The rectangle's centre; on a trimmed surface whose region misses it, the Gauss
    point of a whole cell inside the region nearest to it."""
    import numpy as np

    (_, lu), (_, lv) = surface.domain
    centre = (0.5 * lu, 0.5 * lv)
    from .trim.surface_trim import region_contains

    if surface.trim is None or region_contains(surface, centre):
        return centre
    from .trim import INSIDE
    from .trim.model_matrices import quadrature_of

    quad = quadrature_of(surface)
    points = quad.points[quad.classes[quad.cell[:, 0], quad.cell[:, 1]] == INSIDE]
    best = points[np.argmin(np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1]))]
    return (float(best[0]), float(best[1]))


__all__ = ["ProgressCallback", "RunResult", "make_report", "planned_outputs", "run",
           "summary_rows", "write_outputs"]
