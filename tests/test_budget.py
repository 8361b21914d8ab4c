"""Resources of a run estimated before it starts; refused beyond the budget naming the keys."""
from __future__ import annotations

import math
import re
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
    assert "right-hand sides of rk45" in message


def test_the_highest_frequency_estimate_is_within_its_stated_factor():
    # against the dense eigenproblem: 0.9 <= estimate / ω_max <= 1 on clamped plates and
    # membranes (the docstring states "within 10 % below"; both parts are lower bounds, and a
    # Rayleigh quotient never exceeds λ_max, so 1 holds up to rounding: 1e-9)
    import numpy as np

    import splinedeform as sd
    from splinedeform.budget import highest_frequency

    for cells, degree, weights in [(8, 3, dict(w10=1, w01=1)), (12, 3, dict(w20=1, w11=1, w02=1)),
                                   (8, 1, dict(w10=1, w01=1)), (8, 5, dict(w10=1, w01=1))]:
        model = sd.Model(sd.shapes.plane(cells=cells, degree=degree), sd.Material(**weights),
                         boundary="clamped")
        lam, _ = model.eigen()
        ratio = highest_frequency(model) / np.sqrt(lam.max())
        assert 0.9 <= ratio <= 1.0 + 1e-9, (cells, degree, ratio)


# -- blind spots: work that grows with t_end ω_max, CAD frames, probes and pictures --------
def test_rk45_on_a_stiff_fine_net_over_a_long_span_is_refused_naming_t_end(tmp_path):
    # 32² cells, t_end = 1e4: ω_max ≈ 241, so RK45 needs about 12 x 1e4 x 241 ≈ 3e7
    # right-hand sides (each a sparse solve on 1085 coordinates): hours, refused up front
    text = BASE.replace("cells = 3", "cells = 32").replace("t_end = 2.0", "t_end = 1e4") \
        .replace("frames = 5", 'frames = 5\nmethod = "rk45"')
    message = refusal(text, tmp_path)
    assert message.startswith(f"case.toml:{line_of(text, 't_end')}: solve.t_end: ")
    assert "solve.t_end, solve.method" in message and "right-hand sides of rk45" in message


@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_the_explicit_integrator_estimate_bounds_its_right_hand_sides(method):
    # an independent count: solve_ivp's own nfev on a 6² membrane over 40 time units must
    # lie below the estimate's e t_end ω_max and above a fifth of it (the estimate is an
    # upper-bound-minded order of magnitude; measured ratios 0.26-0.84 on 3² to 32² cells)
    import numpy as np

    from splinedeform.budget import EXPLICIT_EVALUATIONS, highest_frequency

    s = scenario_of(BASE.replace("cells = 3", "cells = 6"))
    built = build(s)
    t_end = 40.0
    solution = built.model.dynamic(built.load, t_end, method=method,
                                   times=np.linspace(0.0, t_end, 5))
    predicted = EXPLICIT_EVALUATIONS[method] * t_end * highest_frequency(built.model)
    assert predicted / 5 <= solution.stats["nfev"] <= predicted


@pytest.mark.parametrize("fmt", ["step", "iges"])
def test_a_hundred_thousand_cad_frames_are_refused(tmp_path, fmt):
    # one NURBS surface per frame: 1e5 STEP/IGES faces of 6 x 6 poles are 1e5 x (2e7 +
    # 36 x 1e5) = 2.37e12 operations (of about 2.4e12 in all) and 5.4 GiB of OpenCASCADE
    # objects
    text = BASE.replace("frames = 5", "frames = 100000").replace(
        "formats = []", f'formats = ["{fmt}"]')
    message = refusal(text, tmp_path)
    assert f"NURBS surfaces of 6 x 6 control points in .{fmt}" in message
    assert "memory: about 5.42 GiB" in message
    assert re.search(rf"work: about 2\.4\d*e\+12 operations \(about [^)]*\) \(100001 NURBS "
                     rf"surfaces of 6 x 6 control points in \.{fmt}\)", message)
    assert "driven by solve.frames, output.formats" in message


def test_a_hundred_thousand_3dm_frames_are_counted():
    # openNURBS: 1e6 + 2e4 G operations per surface (measured 1-1.7 ms a 6 x 6 surface,
    # 4-10 ms a 19 x 19 one); 1e5 + 1 surfaces of 6 x 6 are 1.72e11 operations
    text = BASE.replace("frames = 5", "frames = 100000").replace(
        "formats = []", 'formats = ["3dm"]')
    s = scenario_of(text)
    found = estimate(s, build(s).model)
    cad = next(t for t in found.work if ".3dm" in t.formula)
    assert cad.amount == pytest.approx(100001 * (1e6 + 2e4 * 36), rel=1e-12)   # exact sum
    assert any(".3dm" in t.formula for t in found.disk)


def test_the_3dm_estimate_bounds_the_file_written(tmp_path):
    pytest.importorskip("rhino3dm")
    text = BASE.replace("frames = 5", "frames = 40").replace("formats = []", 'formats = ["3dm"]')
    s = scenario_of(text)
    found = estimate(s, build(s).model)
    run(s, tmp_path / "out")
    size = (tmp_path / "out" / "case.3dm").stat().st_size
    # an upper bound within a factor 4 (measured: 2 KB per 6 x 6 net, estimated 1.5 KiB
    # + the nets' own 24 B per point); no disk term at all before
    assert size <= found.total("disk") <= 4 * size


def test_five_thousand_probes_with_pictures_are_refused_naming_probes(tmp_path):
    # probes.png draws one 800 x 250 panel per probe: 5000 panels are 1.5e12 operations
    # and a 4 GB picture buffer
    probes = ", ".join(f"[{0.1 + 0.8 * i / 4999:.6f}, 0.5]" for i in range(5000))
    text = BASE.replace("formats = []", f'formats = ["images"]\nprobes = [{probes}]')
    message = refusal(text, tmp_path)
    assert f"case.toml:{line_of(text, 'probes')}: output.probes: " in message
    assert "probes.png: 5000 panel" in message


def test_probe_sampling_grows_with_the_probes_and_frames():
    # P (5e4 + 6 F (p + 1)²) operations: 5000 probes over 100 frames of degree 3 are 7.3e8
    def work(probes: int, frames: int) -> float:
        listed = ", ".join(["[0.5, 0.5]"] * probes)
        s = scenario_of(BASE.replace("frames = 5", f"frames = {frames}").replace(
            "formats = []", f"formats = []\nprobes = [{listed}]"))
        return next(t.amount for t in estimate(s, build(s).model).work if "probe" in t.formula)

    assert work(5000, 100) == pytest.approx(5000 * (5e4 + 6 * 100 * 16), rel=1e-12)  # exact
    assert work(1, 100) == pytest.approx(5e4 + 6 * 100 * 16, rel=1e-12)


def test_rendering_is_counted_in_the_work(tmp_path):
    # animations: one 3-D panel of r² samples per frame and format (1.5e8 + 1.5e4 r² + 1e7
    # to encode); 40 frames of GIF and MP4 at r = 64 are 80 x 2.21e8 = 1.77e10 operations
    text = BASE.replace("frames = 5", "frames = 40").replace(
        "formats = []", 'formats = ["gif", "mp4", "images", "viewer"]\nresolution = 64')
    s = scenario_of(text)
    terms = {t.formula: t.amount for t in estimate(s, build(s).model).work}
    rendering = next(a for f, a in terms.items() if f.startswith("rendering 40 animation"))
    assert rendering == pytest.approx(80 * (1.5e8 + 1.5e4 * 64**2 + 1e7), rel=1e-12)
    assert any(f.startswith("pictures: surfaces.png") for f in terms)
    assert any(f.startswith("probes.png: 1 panel") for f in terms)
    assert any(f.startswith("viewer.html") for f in terms)
    assert "rendering 20000 animation frames" in refusal(
        text.replace("frames = 40", "frames = 20000"), tmp_path)


def test_validate_refuses_what_run_refuses_for_its_budget(tmp_path):
    # the same 93.8 GiB case as run's: validate exits 2 (input error) with the same
    # message, and passes once the budget is raised the same way
    from splinedeform import cli

    scenario = tmp_path / "case.toml"
    scenario.write_text(BASE.replace("frames = 5", "frames = 2000").replace(
        "formats = []", "formats = []\nresolution = 1024"))
    runner = CliRunner()
    refused = runner.invoke(cli.app, ["validate", str(scenario)])
    assert refused.exit_code == 2 and "memory: about 93.8 GiB" in refused.output
    assert ": valid" not in refused.output
    allowed = runner.invoke(cli.app, ["validate", str(scenario), "--budget", "memory=100GiB"])
    assert allowed.exit_code == 0 and "estimated memory" in allowed.output


def test_beyond_the_power_limit_the_frequency_estimate_stays_above_the_true_one(monkeypatch):
    # without the factorisation: the Gershgorin rows times 2.5, between 1 and 2.5 times
    # ω_max (the rows lie within a factor 2.5 below it); a 12² plate with the limit lowered
    import numpy as np

    import splinedeform as sd
    from splinedeform import budget

    model = sd.Model(sd.shapes.plane(cells=12, degree=3), sd.Material(w20=1, w11=1, w02=1),
                     boundary="clamped")
    monkeypatch.setattr(budget, "POWER_LIMIT", 10)
    lam, _ = model.eigen()
    ratio = budget.highest_frequency(model) / np.sqrt(lam.max())
    assert 1.0 <= ratio <= 2.5, ratio
