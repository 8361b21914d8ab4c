"""Writing a body's outputs: every face in every file (:mod:`splinedeform.export.body`).

* ``obj`` / ``stl`` / ``ply``: the deformed body (at ``output.time``, else the last frame)
  as one mesh welded across shared edges and seams, with ``patch`` and ``displacement``,
  the triangles of a face its Brep marks reversed wound the other way (normals outward);
* ``vtu``: a ParaView series ``name.pvd`` of welded ``.vtu`` meshes, one per frame (a
  shell's with its stresses, :mod:`splinedeform.outputs_body_shell`);
* ``json`` / ``npz``: ``name_nets.json`` / ``.npz``, every face's nets in every frame keyed
  by its face number, each marked ``reversed`` or not (:mod:`splinedeform.export.body_nets`);
* ``3dm``, ``step``, ``iges``: the deformed body's faces in the file's unit (the ``.3dm``
  one Brep with the body's topology, its faces named, STEP / IGES sewn into one shell,
  trimmed faces bounded by their trim loops and reversed faces reversed);
* ``images``: ``surfaces.png`` (every face at rest and at the frame of largest
  displacement, one welded mesh), ``probes.png`` for a dynamic solve (the probes),
  ``modes.png`` for modes (every mode of the whole body, :func:`splinedeform.viz.
  plot_body_modes`) and for a shell ``stresses.png`` (every face at the frame where von
  Mises peaks);
* ``gif`` / ``mp4``: the whole body's motion, each frame one welded mesh
  (:func:`splinedeform.viz.write_body_animation`; for modes, the lowest mode);
* the per-mode files of a modes solve, every face in each (:mod:`splinedeform.mode_outputs`:
  ``name_modes.vtu``, every mode's nets, and the series and animation of each mode of
  ``output.animate_modes``);
* ``report``: ``report.json`` / ``report.md`` naming the unit, the faces, which are
  reversed, and the topology, and for a shell the stresses per face;
* ``viewer``: ``viewer.html``, every frame of the welded mesh and every face's net, and for
  modes a menu of every mode (:func:`splinedeform.viz.viewer_body.write_body_viewer`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .export.shell_fields import is_shell
from .mode_outputs import mode_file_names, viewer_modes, write_mode_files
from .outputs_body_shell import (body_mode_maxima, body_stress_fields, body_stress_report,
                                 frame_peaks, render_body_stresses)

if TYPE_CHECKING:
    from .outputs import Stages
    from .pipeline import RunResult


def _suffixes() -> dict[str, str]:
    from .outputs import STEP_FILES

    return STEP_FILES


def body_outputs(result: RunResult) -> list[str]:
    """Names of every file :func:`write_body_files` writes, in order."""
    from .export import frame_file_names

    s = result.scenario
    formats, name = s.output.formats, s.name
    names = [f"{name}.{ext}" for ext in ("obj", "stl", "ply") if ext in formats]
    if "vtu" in formats:
        names += [*frame_file_names(name, len(result.times)), f"{name}.pvd"]
    names += [f"{name}_nets.{ext}" for ext in ("json", "npz") if ext in formats]
    names += [f"{name}.3dm"] if "3dm" in formats else []
    names += [f"{name}{suffix}" for ext, suffix in _suffixes().items() if ext in formats]
    if "images" in formats:
        names += ["surfaces.png"] + (["probes.png"] if s.solve.kind == "dynamic" else [])
        names += ["modes.png"] if result.omegas is not None else []
        names += ["stresses.png"] if is_shell(result.built.model) else []
    names += [f"{name}.{ext}" for ext in ("gif", "mp4") if ext in formats]
    names += ["viewer.html"] if "viewer" in formats else []
    names += ["report.json", "report.md"] if "report" in formats else []
    return names + mode_file_names(result)


def face_numbers(result: RunResult) -> list[int]:
    """The file's face number of each patch (the patch index for a body of patches)."""
    body = result.built.surface
    return list(getattr(body, "faces", range(len(body.patches))))


def orientation(result: RunResult) -> tuple[int, ...]:
    """Per patch ``-1`` where the file's Brep marks its face reversed, else ``+1``
    (:attr:`splinedeform.body.Body.orientation`)."""
    body = result.built.surface
    return tuple(getattr(body, "orientation", ()) or (1,) * len(body.patches))


def deformed_nets(result: RunResult) -> list[Any]:
    """Per face the net written as a mesh or CAD file: ``output.time``, else the last frame."""
    time_ = result.scenario.output.time
    if time_ is not None and result.scenario.solve.kind == "dynamic":
        return [np.asarray(n) for n in result.solution.control_points(time_)]
    return [n[-1] for n in result.nets]


def peak_frame(result: RunResult) -> int:
    """The first frame of the largest displacement on the faces' output grids."""
    return int(np.argmax(result.displacement_per_frame))


def write_body_files(result: RunResult, folder: Path, stages: Stages) -> None:
    """Every requested format of a body (module docstring)."""
    from .export import body as body_files

    s = result.scenario
    formats, name, res = s.output.formats, s.name, s.output.resolution
    body, units = result.built.surface, result.built.units
    patches, rest = list(body.patches), result.rest_net
    signs = orientation(result)
    names = [f"{s.name} face {f}" for f in getattr(body, "faces", range(len(patches)))]
    for ext in ("obj", "stl", "ply"):
        if ext in formats:
            with stages.stage(f"mesh .{ext}"):
                result.outputs.append((f"mesh .{ext}", body_files.write_body_mesh(
                    folder / f"{name}.{ext}", patches, deformed_nets(result), rest, res,
                    signs)))
    if "vtu" in formats:
        fields = (body_stress_fields(result.built.model, rest, result.nets, res)
                  if is_shell(result.built.model) else None)
        with stages.stage("time series"):
            result.outputs.append(("time series .pvd", body_files.write_body_series(
                folder, name, patches, rest, result.times, result.nets, res, fields, signs)))
    wanted = [ext for ext in ("json", "npz") if ext in formats]
    if wanted:
        from .export.body_nets import write_body_control_nets

        with stages.stage("control nets"):
            for path in write_body_control_nets(folder, f"{name}_nets", patches,
                                                face_numbers(result), result.times, result.nets,
                                                formats=wanted, orientation=signs):
                result.outputs.append((f"control nets {path.suffix}", path))
    if "3dm" in formats:
        with stages.stage("CAD surfaces"):
            result.outputs.append(("NURBS Brep .3dm", body_files.write_body_3dm(
                folder / f"{name}.3dm", patches, deformed_nets(result), names, units,
                body=body, name=name)))
    for ext, suffix in _suffixes().items():
        if ext in formats:
            with stages.stage(f"CAD surfaces {suffix}"):
                result.outputs.append((f"NURBS surfaces {suffix}", body_files.write_body_step(
                    folder / f"{name}{suffix}", patches, deformed_nets(result), units,
                    orientation=getattr(body, "orientation", None))))
    if "images" in formats:
        _write_images(result, folder, stages)
    for ext in ("gif", "mp4"):
        if ext in formats:
            _write_animation(result, folder / f"{name}.{ext}", stages)
    if "viewer" in formats:
        from .viz.viewer_body import write_body_viewer

        with stages.stage("viewer"):
            result.outputs.append(("viewer", write_body_viewer(
                folder / "viewer.html", patches, rest, result.times, result.nets, res,
                title=s.title or s.name, modes=viewer_modes(result))))
    if mode_file_names(result):
        write_mode_files(result, folder, stages, lambda path, nets, what, label:
                         _write_animation(result, path, stages, nets, what, label))
    if "report" in formats:
        from .outputs import write_report

        write_report(result, folder, stages)


def _write_images(result: RunResult, folder: Path, stages: Stages) -> None:
    from . import viz
    from .outputs import FRAME_LABELS

    s = result.scenario
    label = FRAME_LABELS[s.solve.kind]
    with stages.stage("images"):
        peak = peak_frame(result)
        result.outputs.append(("picture", viz.render_body_surfaces(
            folder / "surfaces.png", list(result.built.surface.patches), result.rest_net,
            [[n[0] for n in result.nets], [n[peak] for n in result.nets]],
            [f"initial ({label} = {result.times[0]:g})",
             f"largest displacement ({label} = {result.times[peak]:.4g})"],
            warp=_warp(result), camera=s.output.camera)))
        if s.solve.kind == "dynamic":
            result.outputs.append(("probe plot", viz.plot_probes(
                folder / "probes.png", result.times, result.probes)))
        if result.omegas is not None:
            result.outputs.append(("mode shapes", viz.plot_body_modes(
                folder / "modes.png", list(result.built.surface.patches), result.omegas,
                result.mode_nets, min(s.output.resolution, 24), orientation(result),
                camera=s.output.camera)))
        model, res = result.built.model, s.output.resolution
        if is_shell(model):
            f = int(np.argmax(frame_peaks(model, result.rest_net, result.nets, res)))
            result.outputs.append(("stress picture", render_body_stresses(
                folder / "stresses.png", model, result.rest_net, [n[f] for n in result.nets],
                f"{label} = {result.times[f]:.4g}", res)))


def _write_animation(result: RunResult, path: Path, stages: Stages, nets: Any = None,
                     what: str = "animation", label: str | None = None) -> None:
    """The body's motion (``nets``, one ``(F, n_u, n_v, 3)`` per patch; default the run's
    frames) as a GIF or MP4, every frame the whole body."""
    from .outputs import FRAME_LABELS
    from .viz import write_body_animation

    s = result.scenario
    stage = f"{what} {path.suffix}"
    with stages.stage(stage):
        result.outputs.append((stage, write_body_animation(
            path, list(result.built.surface.patches), result.rest_net, result.times,
            result.nets if nets is None else nets, resolution=s.output.resolution,
            progress=lambda done, total: stages.tick(stage, done, total + 1),
            fps=s.output.fps, warp=_warp(result), camera=s.output.camera,
            label=label or FRAME_LABELS[s.solve.kind])))


def _warp(result: RunResult) -> float:
    """The pictures' warp factor (:func:`splinedeform.outputs.picture_warp`) on the body's
    box: ``output.warp``, 1 for modes, else :func:`splinedeform.viz.warp.auto_warp`."""
    from .viz.warp import auto_warp

    warp = result.scenario.output.warp
    if warp != "auto":
        return float(warp)
    if result.scenario.solve.kind == "modes":
        return 1.0
    rest = np.concatenate([np.asarray(r).reshape(-1, 3) for r in result.rest_net])
    return auto_warp(float(result.max_displacement), float(np.ptp(rest, axis=0).max()))


def body_report(result: RunResult) -> dict[str, Any]:
    """The content of ``report.json`` / ``report.md`` of a body: inputs, the body (unit,
    faces, topology counts, nets), solver, timings, energies, modes and the faces' centres."""
    from .run_report import assemble_report

    s, body = result.scenario, result.built.surface
    faces = list(getattr(body, "faces", range(len(body))))
    geometry = {"shape": s.surface.shape, "units": result.built.units or "none",
                "faces": faces, "patches": len(body),
                "topology": getattr(body, "counts", None) or body.summary(),
                "interfaces": len(body.interfaces),
                **({"trim edges": body.trim_summary()} if any(p.trim is not None for p in body)
                   else {}),
                "reversed": [sign < 0 for sign in orientation(result)],
                "nets": [f"{p.shape[0]} x {p.shape[1]}" for p in body],
                "degrees": [[p.basis_u.degree, p.basis_v.degree] for p in body],
                "free control points": result.n_free}
    return assemble_report(
        result, "body", geometry, body_mode_maxima,
        lambda label: body_stress_report(result.built.model, faces, result.rest_net,
                                         result.times, result.nets, s.output.resolution,
                                         result.probe_points, result.probe_patches, label))
