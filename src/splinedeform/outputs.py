"""Writing a run's outputs into its folder: meshes, series, nets, pictures, report, manifest.

:func:`write_outputs` claims the folder (:func:`splinedeform.export.claim_folder`: it
locks it and removes what an earlier run of the same scenario wrote and this one will
not), writes every requested format atomically, and writes the manifest last.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from .mode_outputs import mode_file_names, viewer_modes, write_mode_files
from .outputs_body import body_outputs, write_body_files
from .scenario.body import is_body

if TYPE_CHECKING:
    from .pipeline import RunResult


class Stages(Protocol):
    """The pipeline's stage timer: ``stage(name)`` times a block, ``tick`` reports progress."""

    def stage(self, name: str) -> AbstractContextManager[None]: ...

    def tick(self, stage: str, done: int, total: int) -> None: ...


def _mesh_net(result: RunResult) -> Any:
    """The control net written as OBJ/STL/PLY: ``output.time``, else the last frame."""
    time_ = result.scenario.output.time
    if time_ is not None:
        return result.solution.control_points(time_)
    return result.nets[-1]


#: what the frames of each solve kind are called in the pictures
FRAME_LABELS = {"dynamic": "t", "static": "load factor", "modes": "phase"}

#: STEP / IGES output formats and their file suffixes (the 'cad-step' extra)
STEP_FILES = {"step": ".step", "iges": ".igs"}


def planned_outputs(result: RunResult) -> list[str]:
    """Names of every file :func:`write_outputs` writes for this result, in order."""
    from .export import frame_file_names

    s = result.scenario
    if is_body(result.built.surface):
        return body_outputs(result)
    formats, name = s.output.formats, s.name
    names = [f"{name}.{ext}" for ext in ("obj", "stl", "ply") if ext in formats]
    if "vtu" in formats:
        names += [*frame_file_names(name, len(result.times)), f"{name}.pvd"]
    names += [f"{name}_nets.{ext}" for ext in ("json", "npz") if ext in formats]
    names += [f"{name}.3dm"] if "3dm" in formats else []
    names += [f"{name}{STEP_FILES[ext]}" for ext in STEP_FILES if ext in formats]
    if "images" in formats:
        names.append("surfaces.png")
        if s.solve.kind == "dynamic":
            names.append("probes.png")
        if result.omegas is not None:
            names.append("modes.png")
        if getattr(result.built.model, "physics", None) == "shell":
            names.append("stresses.png")
    names += [f"{name}.{ext}" for ext in ("gif", "mp4") if ext in formats]
    names += ["viewer.html"] if "viewer" in formats else []
    names += ["report.json", "report.md"] if "report" in formats else []
    return names + mode_file_names(result)


def write_outputs(result: RunResult, folder: Path, stages: Stages) -> None:
    """Claim the folder (clean what earlier runs of this scenario left), write, manifest last."""
    import re

    from .export import claim_folder

    name = result.scenario.name
    claim = claim_folder(folder, name, planned_outputs(result),
                         frame_pattern=re.escape(name) + r"_\d{4,}\.vtu")
    try:
        result.removed, result.kept = claim.removed, claim.kept
        if is_body(result.built.surface):
            write_body_files(result, folder, stages)
        else:
            _write_files(result, folder, stages)
        with stages.stage("manifest"):
            result.outputs.append(("manifest", claim.finish()))
    finally:
        claim.release()


def _welded_mesh(result: RunResult) -> tuple[Any, Any, Any]:
    """The mesh written as OBJ/STL/PLY: vertices, faces and displacements from rest.

    Tessellated at rest and in the written state; grid points that coincide in both
    (seams, poles) are welded and the triangles that collapse dropped.
    """
    from .export import tessellate_frames, weld

    surface, res = result.built.surface, result.scenario.output.resolution
    X, faces = tessellate_frames(surface, np.stack([result.rest_net, _mesh_net(result)]), res)
    keep, faces = weld(X, faces)
    return X[1, keep], faces, X[1, keep] - X[0, keep]


def _write_files(result: RunResult, folder: Path, stages: Stages) -> None:
    from . import export

    scenario = result.scenario
    formats, name, res = scenario.output.formats, scenario.name, scenario.output.resolution
    surface, rest = result.built.surface, result.rest_net
    times, nets = result.times, result.nets
    for ext in ("obj", "stl", "ply"):
        if ext in formats:
            with stages.stage(f"mesh .{ext}"):
                vertices, faces, d = _welded_mesh(result)
                data = {"displacement": d, "displacement_magnitude": np.linalg.norm(d, axis=1)}
                result.outputs.append((f"mesh .{ext}", export.write_mesh(
                    folder / f"{name}.{ext}", vertices, faces, point_data=data)))
    if "vtu" in formats:
        from .export.shell_fields import is_shell, stress_fields

        model = result.built.model          # a shell's frames also carry its stresses
        fields = stress_fields(model, rest, nets, res) if is_shell(model) else None
        with stages.stage("time series"):
            result.outputs.append(("time series .pvd", export.write_time_series(
                folder, name, surface, rest, times, nets, resolution=res, fields=fields)))
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
                folder / f"{name}.3dm", surface, times, nets, label,
                units=result.built.units, trim=getattr(surface, "trim", None))))
    for ext, suffix in STEP_FILES.items():
        if ext in formats:
            from .cad_step import write_frames_step

            with stages.stage(f"CAD surfaces {suffix}"):
                result.outputs.append((f"NURBS surfaces {suffix}", write_frames_step(
                    folder / f"{name}{suffix}", surface, times, nets, result.built.units,
                    trim=getattr(surface, "trim", None))))
    if "images" in formats:
        _write_images(result, folder, stages)
    for ext in ("gif", "mp4"):
        if ext in formats:
            _write_animation(result, folder / f"{name}.{ext}", stages)
    if "viewer" in formats:
        from .viz import write_viewer

        with stages.stage("viewer"):
            result.outputs.append(("viewer", write_viewer(
                folder / "viewer.html", surface, rest, times, nets, resolution=res,
                title=scenario.title or scenario.name, modes=viewer_modes(result))))
    if mode_file_names(result):
        write_mode_files(result, folder, stages, lambda path, mode_nets, what, label:
                         _write_animation(result, path, stages, mode_nets, what, label))
    if "report" in formats:
        write_report(result, folder, stages)


def write_report(result: RunResult, folder: Path, stages: Stages) -> None:
    """report.json and report.md of :func:`make_report` (a body's: of its report)."""
    from . import export

    with stages.stage("report"):
        result.report = make_report(result)
        paths = export.write_report(folder, result.report)
        result.outputs += [("report .json", paths[0]), ("report .md", paths[1])]


def peak_frame(result: RunResult) -> int:
    """Index of the frame with the largest displacement ``max |B_u (P_f - P_rest) B_vᵀ|``
    on the output grid (the first such frame)."""
    from .export import tessellate_frames

    surface = result.built.surface
    D = result.nets - surface.control_points
    X, _ = tessellate_frames(surface, D, result.scenario.output.resolution)
    return int(np.argmax(np.linalg.norm(X, axis=-1).max(axis=-1)))


#: samples of the probe curves when the solution is known at every time
DENSE_PROBE_SAMPLES = 600


def dense_probes(result: RunResult, samples: int = DENSE_PROBE_SAMPLES
                 ) -> tuple[Any, dict[str, Any]] | None:
    """Probe displacements at ``samples`` times over ``[0, t_end]``, for a solution that is
    exact between frames (the analytic solver); None otherwise.

    Evaluated in chunks of times so that ``chunk × n_u n_v ≤ 4·10⁶`` entries. Each time
    costs up to ``n_free²`` operations (all modes), so fewer samples are taken for large
    nets (at most ``3·10⁹`` operations in all), and none when that is not more than the
    frames.
    """
    solution = result.solution
    if result.scenario.solve.kind != "dynamic" or \
            not getattr(solution, "exact_between_frames", False):
        return None
    samples = min(samples, int(3e9 / max(result.n_free, 1) ** 2))
    if samples <= len(result.times):
        return None
    t = np.union1d(np.linspace(0.0, float(result.scenario.solve.t_end), samples), result.times)
    n_u, n_v = result.built.surface.shape
    chunk = max(1, 4_000_000 // (n_u * n_v * 3))
    out: dict[str, Any] = {}
    for name, (u, v) in result.probe_points.items():
        out[name] = np.concatenate([solution.displacement(t[i:i + chunk], u, v)
                                    for i in range(0, t.size, chunk)])
    if not all(np.all(np.isfinite(d)) for d in out.values()):
        return None
    return t, out


def picture_warp(result: RunResult) -> float:
    """The warp factor of the pictures and the animation: ``output.warp``, or for "auto"
    :func:`splinedeform.viz.warp.auto_warp` of the largest displacement and the largest
    side of the control net's bounding box (1 for a modes solve, whose amplitude is
    chosen for drawing)."""
    from .viz.warp import auto_warp

    warp = result.scenario.output.warp
    if warp != "auto":
        return float(warp)
    if result.scenario.solve.kind == "modes":       # drawn at 10 % of the size already
        return 1.0
    rest = np.asarray(result.rest_net, dtype=float).reshape(-1, 3)
    return auto_warp(float(result.max_displacement), float(np.ptp(rest, axis=0).max()))


def _write_images(result: RunResult, folder: Path, stages: Stages) -> None:
    """surfaces.png (rest shape and the frame of largest displacement), probes.png, modes.png."""
    from . import viz

    surface, rest = result.built.surface, result.rest_net
    kind = result.scenario.solve.kind
    with stages.stage("images"):
        label = FRAME_LABELS[kind]
        peak = peak_frame(result)
        result.outputs.append(("picture", viz.render_surfaces(
            folder / "surfaces.png", surface, rest, [result.nets[0], result.nets[peak]],
            [f"initial ({label} = {result.times[0]:g})",
             f"largest displacement ({label} = {result.times[peak]:.4g})"],
            warp=picture_warp(result), camera=result.scenario.output.camera)))
        if kind == "dynamic":
            dense = dense_probes(result)
            result.outputs.append(("probe plot", viz.plot_probes(
                folder / "probes.png", result.times, result.probes,
                *(dense if dense is not None else (None, None)))))
        if result.omegas is not None:
            result.outputs.append(("mode shapes", viz.plot_modes(
                folder / "modes.png", surface, result.omegas, result.mode_shapes,
                camera=result.scenario.output.camera)))
        from .export.shell_fields import is_shell, peak_stress_frame

        if is_shell(result.built.model):
            from .viz.stresses import render_stresses

            f = peak_stress_frame(result.built.model, rest, result.nets,
                                  result.scenario.output.resolution)
            result.outputs.append(("stress picture", render_stresses(
                folder / "stresses.png", result.built.model, rest, result.nets[f],
                f"{label} = {result.times[f]:.4g}", result.scenario.output.resolution)))


def _write_animation(result: RunResult, path: Path, stages: Stages, nets: Any = None,
                     what: str = "animation", label: str | None = None) -> None:
    from .viz import write_animation

    stage = f"{what} {path.suffix}"
    with stages.stage(stage):
        result.outputs.append((stage, write_animation(
            path, result.built.surface, result.rest_net, result.times,
            result.nets if nets is None else nets,
            resolution=result.scenario.output.resolution,
            progress=lambda done, total: stages.tick(stage, done, total + 1),
            fps=result.scenario.output.fps, warp=picture_warp(result),
            camera=result.scenario.output.camera,
            label=label or FRAME_LABELS[result.scenario.solve.kind])))


def make_report(result: RunResult) -> dict[str, Any]:
    """The content of ``report.json`` / ``report.md``: inputs, solver, timings, energies, probes."""
    if is_body(result.built.surface):
        from .outputs_body import body_report

        return body_report(result)
    from .export.shell_fields import mode_maxima, stress_report
    from .run_report import assemble_report

    surface = result.built.surface
    geometry = {"shape": result.scenario.surface.shape,
                "net": f"{surface.shape[0]} x {surface.shape[1]}",
                "degree": [surface.basis_u.degree, surface.basis_v.degree],
                "knots": [surface.basis_u.kind, surface.basis_v.kind],
                "domain": [list(d) for d in surface.domain],
                "units": result.built.units or "none",
                "fit_error": surface.fit_error,
                _unknowns(result.built.model): result.n_free}
    return assemble_report(
        result, "surface", geometry, mode_maxima,
        lambda label: stress_report(result.built.model, result.rest_net, result.times,
                                    result.nets, result.scenario.output.resolution,
                                    result.probe_points, label))


def summary_rows(result: RunResult) -> list[tuple[str, str]]:
    """(label, value) rows of the closing summary: sizes, times per stage, outputs."""
    s, surface = result.scenario, result.built.surface
    net = (f"{len(surface)} faces, {sum(p.shape[0] * p.shape[1] for p in surface)} points"
           if is_body(surface) else
           f"{surface.shape[0]} x {surface.shape[1]} ({surface.shape[0] * surface.shape[1]} "
           "points)")
    rows = [("scenario", s.title or s.name),
            ("control net", net),
            (_unknowns(result.built.model), str(result.n_free)),
            ("solve", s.solve.kind + (f" ({s.solve.method})" if s.solve.kind == "dynamic"
                                      else "")),
            ("modes", "-" if result.omegas is None else
             f"{len(result.omegas)} (lowest ω = {float(result.omegas[0]):.5g})"),
            ("frames", str(len(result.times))),
            ("max displacement", f"{result.max_displacement:.6g}")]
    rows += [(f"time: {stage}", f"{seconds:.3f} s") for stage, seconds in result.timings.items()]
    rows += [(label, str(path)) for label, path in result.outputs]
    if result.removed:
        names = [p.name for p in result.removed]
        shown = names if len(names) <= 6 else [*names[:3], "…", names[-1]]
        rows.append(("removed", f"{len(names)} file(s) left by an earlier run of this "
                                f"scenario: {', '.join(shown)}"))
    rows += [("kept", f"{path.name}: {why}") for path, why in result.kept]
    return rows


def _unknowns(model: Any) -> str:
    """What the model's free coordinates are called (the shell's are coupled unknowns)."""
    return str(getattr(model, "unknowns_label", "free control points"))
