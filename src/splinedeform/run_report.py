"""Sections of a run's report shared by a single surface (:func:`splinedeform.outputs.
make_report`) and a body (:func:`splinedeform.outputs_body.body_report`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:
    from .pipeline import RunResult


def solver_section(result: RunResult) -> dict[str, Any]:
    """The report's ``solver``: kind, method, end time, frames, largest displacement."""
    solve = result.scenario.solve
    return {"kind": solve.kind, "method": solve.method if solve.kind == "dynamic" else "direct",
            "t_end": solve.t_end if solve.kind == "dynamic" else None,
            "frames": len(result.times), "max displacement": result.max_displacement}


def mode_table(omegas: Any) -> dict[str, Any]:
    """The report's ``modes``: number, ``ω`` and ``ω / 2π`` of each mode."""
    return {"mode": list(range(1, len(omegas) + 1)), "omega": omegas,
            "frequency (omega / 2 pi)": np.asarray(omegas) / (2 * np.pi)}


def add_energies_and_probes(report: dict[str, Any], result: RunResult) -> str:
    """Put the energies and the probes' ``d_x, d_y, d_z, |d|`` per frame into ``report``;
    returns what the frames are called (time, load factor, phase)."""
    if result.energy is not None:
        report["energies"] = result.energy
    label = {"dynamic": "time", "static": "load factor",
             "modes": "phase"}[result.scenario.solve.kind]
    probes: dict[str, Any] = {label: result.times}
    for name, d in result.probes.items():
        probes.update({f"{name} d{c}": d[:, i] for i, c in enumerate("xyz")})
        probes[f"{name} magnitude"] = np.linalg.norm(d, axis=1)
    report["probes"] = probes
    return label


def solution_timings(result: RunResult) -> dict[str, float]:
    timings = getattr(result.solution, "timings", None) or {}
    return {f"solver: {k}": float(v) for k, v in timings.items()}


def assemble_report(result: RunResult, name: str, geometry: dict[str, Any],
                    maxima: Callable[[Any, Any, int], dict[str, Any]],
                    stresses: Callable[[str], dict[str, Any]]) -> dict[str, Any]:
    """``report.json``'s content: the inputs, ``name`` (the surface's or the body's
    ``geometry``), solver, timings, modes, energies and probes; for a shell also each
    mode's largest von Mises, ``maxima(model, shell_modes, resolution)``, and the stresses,
    ``stresses(frame_label)``."""
    import tomllib

    from .export.shell_fields import is_shell
    from .scenario import scenario_to_toml

    s = result.scenario
    report: dict[str, Any] = {
        "inputs": {"source": s.source, **tomllib.loads(scenario_to_toml(s))},
        name: geometry,
        "solver": solver_section(result),
        "timings": {**solution_timings(result), **result.timings},
    }
    shell = is_shell(result.built.model)
    if result.omegas is not None:
        report["modes"] = mode_table(result.omegas)
        if shell and result.shell_modes is not None:
            report["modes"].update(maxima(result.built.model, result.shell_modes,
                                          s.output.resolution))
    label = add_energies_and_probes(report, result)
    if shell:
        report.update(stresses(label))
    return report
