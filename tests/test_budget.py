"""Resources of a run estimated before it starts; refused beyond the budget naming the keys."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from splinedeform import InputError, ScenarioError
from splinedeform.budget import GiB, Budget, estimate
from splinedeform.pipeline import run
from splinedeform.scenario import build, parse_scenario

from tiny_scenario import BASE


def scenario_of(text: str):
    return parse_scenario(text, source="case.toml")


def line_of(text: str, start: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def refusal(text: str, tmp_path: Path, budget: Budget | None = None) -> str:
    out = tmp_path / "out"
    with pytest.raises(ScenarioError) as info:
        run(scenario_of(text), out, budget=budget)
    assert not out.exists() or not any(out.iterdir())        # refused before writing anything
    return str(info.value)


def test_frames_times_resolution_squared_is_refused_for_memory(tmp_path):
    # the case: 2000 frames x 1024² samples x 3 x 8 bytes = 46.9 GiB of surface
    # samples alone; the estimate counts twice that (the samples and their norms/temporaries)
    text = BASE.replace("frames = 5", "frames = 2000").replace(
        "formats = []", "formats = []\nresolution = 1024")
    message = refusal(text, tmp_path)
    assert message.startswith(f"case.toml:{line_of(text, 'frames')}: solve.frames: ")
    assert "memory: about 93.8 GiB" in message and "solve.frames, output.resolution" in message
    assert "--budget" in message


def test_a_hundred_thousand_vtu_frames_are_refused_for_files_and_disk(tmp_path):
    text = BASE.replace("frames = 5", "frames = 100000").replace(
        "formats = []", 'formats = ["vtu"]')
    message = refusal(text, tmp_path)
    assert "files: about 100001" in message and "disk: about" in message
    assert "driven by solve.frames, output.formats" in message


def test_newmark_with_a_tiny_step_is_refused_for_work_naming_dt(tmp_path):
    text = BASE.replace("frames = 5", 'frames = 5\nmethod = "newmark"\ndt = 1e-9')
    message = refusal(text, tmp_path)
    assert message.startswith(f"case.toml:{line_of(text, 'dt')}: solve.dt: ")
    assert "2e+09 time steps of newmark" in message and "solve.dt, solve.t_end" in message


def test_a_raised_budget_lets_the_run_go(tmp_path):
    text = BASE.replace("formats = []", 'formats = ["vtu"]')
    refusal(text, tmp_path, Budget(files=3))
    result = run(scenario_of(text), tmp_path / "out", budget=Budget(files=7))
    assert len(list((tmp_path / "out").iterdir())) == 7      # 5 frames, .pvd, manifest


def test_estimates_bound_what_a_small_run_writes(tmp_path):
    # Files: F + 1 for vtu, one per other format, two for the report (a run may add a
    # manifest of its own); disk is an upper bound by construction (uncompressed sizes).
    text = BASE.replace("formats = []", 'formats = ["vtu", "json", "npz", "report"]')
    s = scenario_of(text)
    found = estimate(s, build(s).model)
    assert found.total("files") == 5 + 1 + 1 + 1 + 2
    run(s, tmp_path / "out")
    written = [p for p in (tmp_path / "out").iterdir()]
    assert found.total("files") <= len(written) <= found.total("files") + 1
    assert sum(p.stat().st_size for p in written) <= found.total("disk") + 2**20


@pytest.mark.parametrize("text, expected", [
    ("memory=16GiB", Budget(memory=16 * GiB)),
    ("memory=16G, disk=500M", Budget(memory=16 * GiB, disk=500 * 2**20)),
    ("files=1e5,work=inf", Budget(files=1e5, work=math.inf)),
    ("", Budget()),
])
def test_budget_text_is_parsed(text, expected):
    assert Budget.parse(text) == expected


@pytest.mark.parametrize("text", ["memory", "ram=4G", "memory=-1", "files=lots", "disk=0"])
def test_bad_budget_text_is_refused(text):
    with pytest.raises(InputError, match="budget"):
        Budget.parse(text)


def test_the_command_line_raises_the_budget(tmp_path):
    from splinedeform import cli

    scenario = tmp_path / "case.toml"
    scenario.write_text(BASE.replace("formats = []", 'formats = ["vtu"]'))
    runner = CliRunner()
    refused = runner.invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "a"), "-q",
                                      "--budget", "files=2"])
    assert refused.exit_code != 0 and "files: about 6" in refused.output
    allowed = runner.invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "b"), "-q",
                                      "--budget", "files=6"])
    assert allowed.exit_code == 0, allowed.output
    valid = runner.invoke(cli.app, ["validate", str(scenario)])
    assert valid.exit_code == 0 and "estimated files" in valid.output


def test_an_adaptive_integrator_over_a_huge_span_is_refused_naming_t_end(tmp_path):
    text = BASE.replace("t_end = 2.0", "t_end = 1e12").replace("frames = 5",
                                                                'frames = 5\nmethod = "rk45"')
    message = refusal(text, tmp_path)
    assert message.startswith(f"case.toml:{line_of(text, 't_end')}: solve.t_end: ")
    assert "steps of rk45" in message


def test_the_highest_frequency_estimate_is_within_its_stated_factor():
    # against the dense eigenproblem: 1/2.5 <= estimate / ω_max <= 1 on clamped plates and
    # membranes (the factor the docstring states)
    import numpy as np

    import splinedeform as sd
    from splinedeform.budget import highest_frequency

    for cells, degree, weights in [(8, 3, dict(w10=1, w01=1)), (12, 3, dict(w20=1, w11=1, w02=1)),
                                   (8, 1, dict(w10=1, w01=1)), (8, 5, dict(w10=1, w01=1))]:
        model = sd.Model(sd.shapes.plane(cells=cells, degree=degree), sd.Material(**weights),
                         boundary="clamped")
        lam, _ = model.eigen()
        ratio = highest_frequency(model) / np.sqrt(lam.max())
        assert 1 / 2.5 <= ratio <= 1.0, (cells, degree, ratio)
