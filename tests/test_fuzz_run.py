"""Mutated scenarios run end to end: a result or a located ScenarioError, nothing else.

Each example starts from a tiny valid scenario (a 2-cell plane, three frames), applies one
to four mutations drawn from every key of every table (mostly values real scenarios use, so
that many mutants run, besides extremes such as 1e308, 1e-320, inf and NaN, wrong types,
unknown and missing keys) and runs it through
:func:`splinedeform.pipeline.run` into a temporary folder with a small budget. The run must
either finish or raise a :class:`ScenarioError` whose message starts with ``case.toml:``;
any other exception is a bug.

The suite runs 200 examples; for a long campaign set ``SPLINEDEFORM_FUZZ_EXAMPLES``, e.g.
``SPLINEDEFORM_FUZZ_EXAMPLES=5000 .venv/bin/python -m pytest -q tests/test_fuzz_run.py``.
"""

from __future__ import annotations

import copy
import math
import os
import re
import tempfile
import warnings
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from splinedeform import ScenarioError
from splinedeform.budget import Budget
from splinedeform.pipeline import run
from splinedeform.scenario import _toml_value, parse_scenario

EXAMPLES = int(os.environ.get("SPLINEDEFORM_FUZZ_EXAMPLES", "200"))
#: small enough that a refused run costs nothing and an accepted one stays quick
BUDGET = Budget(memory=256 * 2**20, disk=32 * 2**20, files=100, work=2e9)
LOCATED = re.compile(r"^case\.toml(:\d+: \S| ?: \d+ problems)")

BASE = {
    "title": "fuzz",
    "surface": {"shape": "plane", "cells": 2, "degree": 2},
    "material": {"w10": 1.0, "w01": 1.0},
    "boundary": {"u0": "clamped"},
    "load": [{"kind": "uniform", "force": [0.0, 0.0, -1.0]}],
    "solve": {"kind": "dynamic", "t_end": 1.0, "frames": 3},
    "output": {"formats": ["report", "json"], "resolution": 4},
}

EXTREME = st.sampled_from([0.0, -0.0, -1.0, 1e-320, 1e-300, 1e-100, 0.5, 1.0, 3.0, 1e100,
                           1e300, 1e308, -1e308, math.inf, -math.inf, math.nan])
NUMBER = EXTREME | st.floats(allow_nan=True, allow_infinity=True) | st.integers(-10, 10)
WRONG = st.none() | st.booleans() | st.text(max_size=6) | st.just([]) | st.just({})
PAIR = st.lists(NUMBER, min_size=0, max_size=3)
SMALL_INT = st.integers(-2, 9) | st.sampled_from([0, 512, 10**6, 2**31, 10**20])

VALUES = {
    "surface.shape": st.sampled_from(["plane", "saddle", "tile", "half_sphere", "cylinder",
                                      "torus", "file", "cube"]),
    "surface.cells": SMALL_INT | st.lists(SMALL_INT, min_size=1, max_size=3),
    "surface.degree": SMALL_INT,
    "surface.knots": st.sampled_from(["open", "uniform", "periodic", "closed",
                                      ["periodic", "open"], ["open", "periodic"],
                                      ["periodic", "periodic"]]),
    "surface.method": st.sampled_from(["interpolate", "l2", "quasi", "spline"]),
    "surface.size": NUMBER | PAIR, "surface.radius": NUMBER, "surface.angle": NUMBER,
    "surface.height": NUMBER, "surface.length": NUMBER, "surface.R": NUMBER,
    "surface.r": NUMBER, "surface.path": st.sampled_from(["net.json", "../x.npy", "/etc/passwd"]),
    "material.mass": NUMBER, "material.damping": NUMBER, "material.rayleigh": NUMBER,
    "material.w10": NUMBER, "material.w01": NUMBER, "material.w20": NUMBER,
    "material.w11": NUMBER, "material.w02": NUMBER,
    "material.mass_matrix": st.sampled_from(["consistent", "lumped", "diagonal"]),
    "material.physics": st.sampled_from(["parametric", "intrinsic", "shell"]),
    "boundary.u0": st.sampled_from(["free", "pinned", "clamped", "pole", "glued"]),
    "boundary.u1": st.sampled_from(["free", "pinned", "clamped", "pole"]),
    "boundary.v0": st.sampled_from(["free", "pinned", "clamped", "pole"]),
    "boundary.v1": st.sampled_from(["free", "pinned", "clamped", "pole"]),
    "boundary.free_u": PAIR, "boundary.free_v": PAIR,
    "load.kind": st.sampled_from(["point", "uniform", "pressure", "gravity"]),
    "load.at": PAIR, "load.force": st.lists(NUMBER, min_size=2, max_size=4),
    "load.q": NUMBER,
    "load.profile": st.sampled_from(["constant", "step", "piecewise", "harmonic", "ramp"]),
    "load.t_on": NUMBER, "load.t_off": NUMBER, "load.omega": NUMBER, "load.phase": NUMBER,
    "load.points": st.lists(PAIR, max_size=3),
    "solve.kind": st.sampled_from(["static", "dynamic", "modes", "transient"]),
    "solve.method": st.sampled_from(["analytic", "newmark", "genalpha", "radau3", "rk45",
                                     "dop853", "radau", "bdf", "euler"]),
    "solve.t_end": NUMBER, "solve.frames": SMALL_INT, "solve.times": st.lists(NUMBER, max_size=4),
    "solve.modes": SMALL_INT, "solve.dt": NUMBER, "solve.rtol": NUMBER, "solve.atol": NUMBER,
    "solve.function_samples": SMALL_INT,
    "output.formats": st.lists(st.sampled_from(["report", "json", "npz", "obj", "stl", "ply",
                                                "vtu", "viewer", "nets", "pvd", "pdf"]),
                               max_size=4, unique=True),
    "output.resolution": SMALL_INT, "output.probes": st.lists(PAIR, max_size=2),
    "output.time": NUMBER,
    "output.warp": NUMBER | st.sampled_from(["auto", "big", ""]), "output.camera": PAIR,
    "output.fps": NUMBER, "output.animate_modes": st.lists(SMALL_INT, max_size=3),
}
PATHS = sorted(VALUES)
#: values each key takes in real scenarios, so that many mutants get past reading and run
PLAUSIBLE = {
    "surface.shape": st.sampled_from(["plane", "saddle", "tile", "half_sphere", "cylinder",
                                      "torus"]),
    "surface.cells": st.integers(1, 5), "surface.degree": st.integers(1, 3),
    "surface.knots": st.sampled_from(["open", "uniform", "periodic"]),
    "surface.method": st.sampled_from(["interpolate", "l2", "quasi"]),
    "material.mass": st.floats(0.1, 10.0), "material.damping": st.floats(0.0, 5.0),
    "material.rayleigh": st.floats(0.0, 0.1), "material.w10": st.floats(0.0, 5.0),
    "material.w01": st.floats(0.0, 5.0), "material.w20": st.floats(0.0, 1.0),
    "material.w11": st.floats(0.0, 1.0), "material.w02": st.floats(0.0, 1.0),
    "material.mass_matrix": st.sampled_from(["consistent", "lumped"]),
    "material.physics": st.sampled_from(["parametric", "intrinsic"]),
    "boundary.u0": st.sampled_from(["free", "pinned", "clamped"]),
    "boundary.u1": st.sampled_from(["free", "pinned", "clamped"]),
    "boundary.v0": st.sampled_from(["free", "pinned", "clamped"]),
    "boundary.v1": st.sampled_from(["free", "pinned", "clamped"]),
    "load.profile": st.sampled_from(["constant", "step"]),
    "load.t_on": st.floats(0.0, 1.0), "load.force": st.lists(st.floats(-2.0, 2.0), min_size=3,
                                                             max_size=3),
    "solve.kind": st.sampled_from(["static", "dynamic", "modes"]),
    "solve.method": st.sampled_from(["analytic", "newmark", "genalpha", "radau3", "rk45",
                                     "dop853", "radau", "bdf"]),
    "solve.t_end": st.floats(0.01, 3.0), "solve.frames": st.integers(1, 6),
    "solve.modes": st.integers(0, 6),
    "output.formats": st.lists(st.sampled_from(["report", "json", "npz", "obj", "stl", "ply",
                                                "vtu", "viewer"]), max_size=3, unique=True),
    "output.resolution": st.integers(2, 8),
}


@st.composite
def mutations(draw) -> list[tuple[str, str, object]]:
    """1 to 4 edits ``(action, key path, value)``: set, set to a wrong type, delete, add."""
    edits = []
    for _ in range(draw(st.integers(1, 4))):
        path = draw(st.sampled_from(PATHS))
        action = draw(st.sampled_from(["plausible"] * 6 + ["set"] * 3
                                      + ["wrong", "delete", "unknown"]))
        if action == "plausible" and path in PLAUSIBLE:
            value = draw(PLAUSIBLE[path])
        else:
            value = draw(WRONG) if action == "wrong" else draw(VALUES[path])
        edits.append((action, path, value))
    return edits


def mutated(edits: list[tuple[str, str, object]]) -> dict:
    doc = copy.deepcopy(BASE)
    for action, path, value in edits:
        table, key = path.split(".")
        target = doc["load"][0] if table == "load" else doc.setdefault(table, {})
        if action == "delete":
            target.pop(key, None)
        elif action == "unknown":
            target[key + "_x"] = value
        else:
            target[key] = value
    return doc


def toml(doc: dict) -> str:
    """TOML text: top-level strings, then each table (``[[load]]`` as an array of tables)."""
    def clean(value):
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items() if v is not None}
        if isinstance(value, list):
            return [clean(v) for v in value if v is not None]
        return value
    doc = clean(doc)
    lines = [f"{k} = {_toml_value(v)}" for k, v in doc.items() if not isinstance(v, (dict, list))]
    for name, table in doc.items():
        tables = table if name == "load" and isinstance(table, list) else [table]
        for item in tables:
            if not isinstance(item, dict):
                continue
            lines.append(f"[[{name}]]" if name == "load" else f"[{name}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in item.items()]
    return "\n".join(lines) + "\n"


def run_text(text: str, folder: Path) -> None:
    """Run ``text``; pass on success or a located ScenarioError, raise anything else."""
    from splinedeform.export import write_control_nets
    from splinedeform.shapes import plane

    surface = plane(cells=2, degree=2)
    write_control_nets(folder, "net", surface, [0.0], surface.control_points[None])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")           # overflow warnings are fine; results are checked
        try:
            scenario = parse_scenario(text, source="case.toml", directory=folder)
            run(scenario, folder / "out", budget=BUDGET)
        except ScenarioError as exc:
            assert LOCATED.match(str(exc)), f"not located: {exc}\n--- scenario:\n{text}"


def test_the_base_scenario_runs():
    with tempfile.TemporaryDirectory() as folder:
        run_text(toml(BASE), Path(folder))
        assert (Path(folder) / "out" / "report.json").is_file()


@settings(max_examples=EXAMPLES, deadline=None, derandomize=EXAMPLES <= 200,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(edits=mutations())
def test_mutated_scenarios_run_or_fail_located(edits):
    with tempfile.TemporaryDirectory() as folder:
        run_text(toml(mutated(edits)), Path(folder))
