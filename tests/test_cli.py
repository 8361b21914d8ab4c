"""The ``splinedeform`` command line, driven in-process by typer's CliRunner."""

from __future__ import annotations

import importlib
import importlib.machinery
import json
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import BSplineBasis, Surface, __version__
from splinedeform import cli
from splinedeform.export import write_control_nets

runner = CliRunner()

SCENARIO = """
title = "tiny membrane"

[surface]
shape = "file"
path = "square.json"

[material]
w10 = 1.0
w01 = 1.0
damping = 1.0

[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"

[[load]]
kind = "uniform"
force = [0.0, 0.0, -1.0]

[solve]
kind = "dynamic"
t_end = 1.0
frames = 4
modes = 2

[output]
formats = ["obj", "ply", "vtu", "json", "report"]
resolution = 6
"""


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    """A 5 x 5 net of the unit square (open knots, degree 2) and a scenario using it."""
    basis = BSplineBasis(2, 3, 1.0, "open")
    g = basis.greville()
    P = np.stack(np.broadcast_arrays(g[:, None], g[None, :], 0.0 * g[:, None]), -1)
    write_control_nets(tmp_path, "square", Surface(P, basis, basis), [0.0], P[None])
    path = tmp_path / "tiny.toml"
    path.write_text(SCENARIO)
    return path


def summary_paths(output: str) -> dict[str, Path]:
    """Rows of the summary table whose value is an existing-looking file path."""
    rows = {}
    for line in output.splitlines():
        cells = [c.strip() for c in line.strip("│┃ ").split("│")]
        if len(cells) == 2 and cells[1].startswith("/"):
            rows[cells[0]] = Path(cells[1])
    return rows


def test_run_writes_the_files_listed_in_the_summary(scenario, tmp_path):
    out = tmp_path / "out"
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    listed = summary_paths(result.stdout)
    assert set(listed) == {"mesh .obj", "mesh .ply", "time series .pvd", "control nets .json",
                           "report .json", "report .md", "manifest"}
    for path in listed.values():
        assert path.is_file() and path.parent == out
    written = {p.name for p in out.iterdir()}
    assert written == {p.name for p in listed.values()} | {f"tiny_000{i}.vtu" for i in range(4)}
    report = json.loads((out / "report.json").read_text())
    assert report["solver"]["frames"] == 4 and report["surface"]["net"] == "5 x 5"
    assert report["surface"]["free control points"] == 9     # pinned: the 3 x 3 inner points
    assert "free control points" in result.stdout and "max displacement" in result.stdout


def test_frames_and_method_override_the_file(scenario, tmp_path):
    out = tmp_path / "out"
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(out), "--frames", "3",
                                     "--method", "newmark", "--quiet"])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["solver"]["frames"] == 3 and report["solver"]["method"] == "newmark"


def test_quiet_prints_nothing(scenario, tmp_path):
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "o"), "-q"])
    assert result.exit_code == 0
    assert result.stdout == "" and result.stderr == ""


def test_input_errors_exit_2_with_the_message_and_no_traceback(scenario, tmp_path):
    scenario.write_text(SCENARIO.replace("t_end = 1.0", "t_end = -1.0"))
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "o"), "-q"])
    assert result.exit_code == 2
    line = SCENARIO.splitlines().index("t_end = 1.0") + 1
    assert f"tiny.toml:{line}: solve.t_end: expected a number > 0" in result.stderr
    assert "Traceback" not in result.output and result.stdout == ""


def test_override_errors_name_the_option(scenario, tmp_path):
    result = runner.invoke(cli.app, ["run", str(scenario), "--method", "euler", "-q"])
    assert result.exit_code == 2
    assert "tiny.toml (--method): solve.method: expected one of" in result.stderr


def test_debug_lets_the_exception_through(scenario):
    result = runner.invoke(cli.app, ["run", str(scenario), "--method", "euler", "--debug"])
    assert result.exit_code == 1
    assert type(result.exception).__name__ == "ScenarioError"


def test_missing_file_is_an_input_error(tmp_path):
    result = runner.invoke(cli.app, ["validate", str(tmp_path / "nope.toml")])
    assert result.exit_code == 2 and "scenario file not found" in result.stderr


def test_unexpected_errors_exit_1_without_traceback(scenario, tmp_path, monkeypatch):
    import splinedeform.pipeline as sc

    def broken(*args, **kwargs):
        raise RuntimeError("disk on fire")
    monkeypatch.setattr(sc, "run", broken)
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "o")])
    assert result.exit_code == 1
    assert "internal error: RuntimeError: disk on fire" in result.stderr
    assert "--debug" in result.stderr and "Traceback" not in result.output


def test_validate_prints_the_effective_scenario(scenario):
    result = runner.invoke(cli.app, ["validate", str(scenario)])
    assert result.exit_code == 0, result.output
    assert "valid" in result.stdout and "5 x 5 (25 points)" in result.stdout
    toml_part = result.stdout[result.stdout.index('title = "tiny membrane"'):]
    import tomllib

    effective = tomllib.loads(toml_part)
    assert effective["material"]["mass"] == 1.0              # default filled in
    assert effective["solve"]["method"] == "analytic"
    assert effective["boundary"]["u0"] == "pinned"


def test_validate_reports_every_problem(scenario):
    scenario.write_text(SCENARIO.replace("frames = 4", "frames = 1")
                        .replace('kind = "uniform"', 'kind = "gravity"'))
    result = runner.invoke(cli.app, ["validate", str(scenario)])
    assert result.exit_code == 2
    assert "2 problems" in result.stderr
    assert "load[1].kind" in result.stderr and "solve.frames" in result.stderr


def test_info_names_version_extras_and_examples():
    result = runner.invoke(cli.app, ["info"])
    assert result.exit_code == 0
    assert __version__ in result.stdout
    for dist in ("meshio", "matplotlib", "imageio-ffmpeg", "pyvista", "rhino3dm",
                 "cadquery-ocp-novtk"):
        assert dist in result.stdout
    examples = cli.examples_directory()
    assert examples is not None and _unwrapped(str(examples)) in _unwrapped(result.stdout)


def _unwrapped(text: str) -> str:
    """Text without table borders and line breaks (long values wrap inside their cell)."""
    return "".join(ch for ch in text if ch not in "│┃┌┐└┘├┤┬┴┼─ \n")


def test_info_fits_in_100_columns(monkeypatch):
    monkeypatch.setattr(cli, "examples_directory",       # a deep checkout: paths wrap
                        lambda: Path("/" + "/".join(["a-rather-long-folder-name"] * 8)))
    result = runner.invoke(cli.app, ["info"])
    assert result.exit_code == 0
    widths = [len(line) for line in result.stdout.splitlines()]
    assert max(widths) <= cli.INFO_WIDTH, max(widths)
    assert "example files" in result.stdout


def test_version_prints_the_version():
    result = runner.invoke(cli.app, ["--version"])
    assert result.exit_code == 0 and result.stdout == f"splinedeform {__version__}\n"


def _command_names() -> list[list[str]]:
    import typer.main

    return [[]] + [[name] for name in typer.main.get_command(cli.app).commands]


@pytest.mark.parametrize("command", _command_names(), ids=lambda c: " ".join(c) or "splinedeform")
def test_help_shows_flags_bare(command):
    result = runner.invoke(cli.app, [*command, "--help"])
    assert result.exit_code == 0, result.output
    assert "<bool>" not in result.stdout
    if command in (["run"], ["demo"], ["bench"]):
        assert "--quiet" in result.stdout


def test_bench_is_forwarded_when_the_module_exists(monkeypatch, tmp_path):
    importlib.import_module("splinedeform.bench_goals")   # reads the real bench on import
    calls = []
    fake = types.ModuleType("splinedeform.bench")
    fake.__spec__ = importlib.machinery.ModuleSpec("splinedeform.bench", None)
    fake.main = lambda sizes, quick, outdir, quiet: calls.append((sizes, quick, outdir, quiet))
    monkeypatch.setitem(sys.modules, "splinedeform.bench", fake)
    import splinedeform

    monkeypatch.setattr(splinedeform, "bench", fake, raising=False)
    fresh = importlib.reload(cli)
    try:
        result = runner.invoke(fresh.app, ["bench", "--sizes", "4,8", "--quick", "-o",
                                           str(tmp_path), "--quiet"])
        assert result.exit_code == 0, result.output
        assert calls == [([4, 8], True, tmp_path, True)]
        plain = runner.invoke(fresh.app, ["bench", "--quick"])
        assert plain.exit_code == 0, plain.output
        assert "BLAS threads" not in plain.output              # bench.main says it, once
        assert calls[-1][2] == fresh.BENCH_OUTDIR == Path("out", "bench")
        ignored = (Path(__file__).resolve().parents[1] / ".gitignore").read_text().split()
        assert "out/" in ignored                     # the default folder is git-ignored
        bad = runner.invoke(fresh.app, ["bench", "--sizes", "4,x"])
        assert bad.exit_code == 2 and "--sizes must be comma-separated integers" in bad.stderr
    finally:
        monkeypatch.undo()
        importlib.reload(cli)


def test_demo_runs_the_built_in_half_sphere(tmp_path):
    pytest.importorskip("splinedeform.shapes")
    out = tmp_path / "demo"
    result = runner.invoke(cli.app, ["demo", "-o", str(out)])
    assert result.exit_code == 0, result.output
    listed = summary_paths(result.stdout)
    assert all(path.is_file() for path in listed.values())
    names = {p.name for p in listed.values()}
    assert {"report.json", "viewer.html", "surfaces.png", "modes.png", "demo.gif",
            "demo.pvd", "demo_nets.json", "demo.obj"} <= names
    report = json.loads((out / "report.json").read_text())
    assert report["inputs"]["surface"]["shape"] == "half_sphere"
    assert report["solver"]["kind"] == "dynamic" and report["solver"]["method"] == "analytic"
    assert report["inputs"]["load"][0]["kind"] == "point"


def test_info_reports_a_missing_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyvista", None)    # import fails like a missing package
    result = runner.invoke(cli.app, ["info"])
    assert result.exit_code == 0
    row = next(line for line in result.stdout.splitlines() if "pyvista" in line)
    assert "not installed" in row


def test_physics_option_selects_the_energy_and_names_a_bad_value(scenario, tmp_path):
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "o"),
                                     "--physics", "intrinsic", "-q"])
    assert result.exit_code == 0, result.output
    result = runner.invoke(cli.app, ["run", str(scenario), "--physics", "membrane", "-q"])
    assert result.exit_code == 2
    assert "tiny.toml (--physics): material.physics: expected one of" in result.stderr
    # the shell takes E, nu, thickness instead of the plate's weights: named where they are
    result = runner.invoke(cli.app, ["run", str(scenario), "--physics", "shell", "-q"])
    assert result.exit_code == 2
    assert "material.E: missing (physics \"shell\" needs it)" in result.stderr
    assert "material.w10: does not apply to physics \"shell\"" in result.stderr


EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("name, method, dropped", [
    ("torus_point_rk45", "analytic", ["solve.rtol", "solve.atol"]),
    ("saddle_gravity_newmark", "analytic", ["solve.dt"]),
    ("saddle_gravity_newmark", "rk45", ["solve.dt"]),
    ("torus_point_rk45", "newmark", ["solve.rtol", "solve.atol"]),
    ("torus_point_rk45", "dop853", []),                  # rtol/atol apply to both
])
def test_method_override_drops_the_settings_of_the_old_method(name, method, dropped):
    from splinedeform.scenario import load_scenario, with_method

    scenario, removed = with_method(load_scenario(EXAMPLES / f"{name}.toml"), method)
    assert removed == dropped
    assert scenario.solve.method == method
    assert not set(k.split(".")[1] for k in dropped) & set(scenario.raw["solve"])


def test_method_override_of_an_example_runs_and_says_what_it_dropped(tmp_path):
    out = tmp_path / "out"
    args = ["run", str(EXAMPLES / "torus_point_rk45.toml"), "-o", str(out), "--frames", "3",
            "--method", "analytic"]
    result = runner.invoke(cli.app, args)
    assert result.exit_code == 0, result.output
    notes = [line for line in result.stderr.splitlines() if "dropped" in line]
    assert len(notes) == 1
    assert "solve.rtol, solve.atol" in notes[0] and "'rk45'" in notes[0]
    assert json.loads((out / "report.json").read_text())["solver"]["method"] == "analytic"
    quiet = runner.invoke(cli.app, args + ["--quiet"])
    assert quiet.exit_code == 0 and quiet.stderr == "" and quiet.stdout == ""


def test_unknown_method_is_refused_not_dropped(scenario):
    result = runner.invoke(cli.app, ["run", str(scenario), "--method", "euler"])
    assert result.exit_code == 2 and "dropped" not in result.stderr
