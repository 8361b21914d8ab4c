"""Sweep files: reading and located errors, the designs, the cases and their hashes, one task.

Nothing here starts a Dask cluster (tests/test_sweep_dask.py does): the task of one model
group, :func:`splinedeform.study.solve.solve_group`, runs in this process.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from splinedeform import ScenarioError
from splinedeform.study import load_sweep
from splinedeform.study.cases import plan_cases
from splinedeform.study.design import design_points
from splinedeform.study.solve import solve_group
from splinedeform.study.store import case_file, write_tables

from sweep_files import write

AXES = """\
scenario = "base.toml"

[[axis]]
key = "material.damping"
values = [0.5, 2.0]

[[axis]]
key = "load[1].at"
values = [[0.5, 0.5], [0.3, 0.6], [0.7, 0.2]]
"""


def error_of(tmp_path, text: str) -> str:
    with pytest.raises(ScenarioError) as info:
        load_sweep(write(tmp_path, text))
    return str(info.value)


def line_of(text: str, start: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def test_an_unknown_axis_key_is_refused_naming_the_axis_and_its_line(tmp_path):
    text = AXES.replace('key = "material.damping"', 'key = "material.stiffness"')
    message = error_of(tmp_path, text)
    line = line_of(text, 'key = "material.stiffness')
    assert f"study.toml:{line}: axis[1].key" in message
    assert "axis 'material.stiffness' is refused" in message and "w20" in message


@pytest.mark.parametrize("key, says", [
    ("load[2].at", "has 1 [[load]] table"),
    ("load.0.at", "has 1 [[load]] table"),
    ("load[1].position", "is not a key of [load]"),
    ("solid.E", "no table [solid]"),
    ("w20", "names its table"),
])
def test_keys_the_base_scenario_does_not_have_are_refused(tmp_path, key, says):
    message = error_of(tmp_path, AXES.replace('"load[1].at"', f'"{key}"'))
    assert "axis[2].key" in message and says in message, message


def test_every_problem_of_a_sweep_file_is_reported_at_its_line(tmp_path):
    text = """\
scenario = "base.toml"
colour = "red"

[design]
kind = "random"

[[axis]]
key = "material.w10"
range = [2.0, 1.0]
scale = "log"

[[axis]]
key = "material.w01"
values = [1.0]
count = 3
"""
    message = error_of(tmp_path, text)
    assert "4 problems in the sweep file" in message, message
    assert "study.toml:2: colour: unknown key" in message
    assert "study.toml:4: design.n: missing: a random design draws n cases" in message
    assert "study.toml:9: axis[1].range: expected low < high, got [2, 1]" in message
    assert "study.toml:15: axis[2].count: applies to range only" in message


def test_a_missing_base_scenario_names_the_scenario_key(tmp_path):
    message = error_of(tmp_path, AXES.replace('"base.toml"', '"nowhere.toml"'))
    assert "study.toml:1: scenario: the base scenario" in message and "nowhere.toml" in message


def test_a_grid_is_every_combination_first_axis_slowest(tmp_path):
    sweep = load_sweep(write(tmp_path, AXES))
    points = design_points(sweep)
    assert [(p["material.damping"], p["load[1].at"]) for p in points] == [
        (0.5, [0.5, 0.5]), (0.5, [0.3, 0.6]), (0.5, [0.7, 0.2]),
        (2.0, [0.5, 0.5]), (2.0, [0.3, 0.6]), (2.0, [0.7, 0.2])]


def test_a_log_range_is_a_geometric_sequence(tmp_path):
    text = 'scenario = "base.toml"\n[[axis]]\nkey = "material.w10"\nrange = [0.01, 100.0]\n' \
           'count = 5\nscale = "log"\n'
    values = [p["material.w10"] for p in design_points(load_sweep(write(tmp_path, text)))]
    # 0.01 · 10^(2i): exact in exp/log up to a few ulps, hence 1e-12 relative
    np.testing.assert_allclose(values, [0.01, 0.1, 1.0, 10.0, 100.0], rtol=1e-12)


def test_a_latin_hypercube_puts_one_point_in_each_stratum_of_each_axis(tmp_path):
    text = """\
scenario = "base.toml"
[design]
kind = "latin-hypercube"
n = 20
seed = 7
[[axis]]
key = "material.w10"
range = [1.0, 3.0]
[[axis]]
key = "material.damping"
range = [0.1, 10.0]
scale = "log"
"""
    points = design_points(load_sweep(write(tmp_path, text)))
    w10 = np.array([p["material.w10"] for p in points])
    damping = np.array([p["material.damping"] for p in points])
    # stratum k of n of [1, 3] is [1 + 2k/n, 1 + 2(k+1)/n): each holds exactly one point
    assert sorted(np.floor((w10 - 1.0) / 2.0 * 20).astype(int)) == list(range(20))
    assert sorted(np.floor(np.log(damping / 0.1) / np.log(100.0) * 20).astype(int)) == \
        list(range(20))
    again = design_points(load_sweep(write(tmp_path / "again", text)))
    assert again == points      # the seed fixes the draw


def test_cases_differing_only_in_loads_share_a_model_and_every_case_has_its_own_hash(tmp_path):
    cases = plan_cases(load_sweep(write(tmp_path, AXES)))
    assert len(cases) == 6 and len({c.hash for c in cases}) == 6
    assert len({c.model for c in cases}) == 2       # two dampings; the load places share
    assert [c.index for c in cases] == [1, 2, 3, 4, 5, 6]


def test_a_value_the_key_does_not_allow_fails_its_case_with_the_readers_message(tmp_path):
    text = AXES.replace("values = [0.5, 2.0]", "values = [0.5, -1.0]")
    cases = plan_cases(load_sweep(write(tmp_path, text)))
    refused = [c for c in cases if c.error is not None]
    assert [c.index for c in refused] == [4, 5, 6]
    assert "(axis material.damping = -1.0): material.damping: expected a number >= 0" in \
        refused[0].error, refused[0].error


def test_one_task_solves_its_cases_on_one_model_and_skips_those_stored(tmp_path):
    cases = plan_cases(load_sweep(write(tmp_path, AXES)))
    group = [c for c in cases if c.model == cases[0].model]
    out = tmp_path / "out"
    rows = solve_group(group, str(out))
    assert [r["status"] for r in rows] == ["ok"] * 3
    assert all(case_file(out, c.hash).is_file() for c in group)
    # the probe at the load's point moves most when the load is there: p1 sits at (0.5, 0.5)
    assert rows[0]["p1_max"] > rows[1]["p1_max"] and rows[0]["p1_max"] > rows[2]["p1_max"]
    inodes = [case_file(out, c.hash).stat().st_ino for c in group]
    again = solve_group(group, str(out))
    assert again == rows
    assert [case_file(out, c.hash).stat().st_ino for c in group] == inodes


def test_a_case_that_raises_gets_its_error_in_its_row_and_the_others_go_on(tmp_path):
    static = """\
[surface]
shape = "plane"
cells = 3

[material]
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "clamped"

[[load]]
kind = "uniform"
force = [0.0, 0.0, -1.0]

[solve]
kind = "static"
frames = 2

[output]
formats = []
"""
    text = 'scenario = "base.toml"\n[[axis]]\nkey = "boundary.u0"\nvalues = ["free", "clamped"]\n'
    cases = plan_cases(load_sweep(write(tmp_path, text, scenario=static)))
    rows = [row for c in cases for row in solve_group([c], str(tmp_path / "out"))]
    assert "unconstrained surface" in rows[0]["status"] and "base.toml" in rows[0]["status"]
    assert rows[1]["status"] == "ok" and rows[1]["max_displacement"] > 0


def test_tables_hold_one_row_per_case_with_list_values_as_columns(tmp_path):
    pa = pytest.importorskip("pyarrow.parquet")
    rows = [{"case": 1, "values": {"load[1].at": [0.5, 0.25]}, "status": "ok", "x": 1.5},
            {"case": 2, "values": {"load[1].at": [0.3, 0.6]}, "status": "bad: no", "x": None}]
    csv_path, parquet_path = write_tables(tmp_path, rows)
    table = pa.read_table(parquet_path).to_pylist()
    assert [r["load[1].at[2]"] for r in table] == [0.25, 0.6]
    assert table[0]["x"] == 1.5 and math.isnan(table[1]["x"])
    assert csv_path.read_text().splitlines()[0] == "case,load[1].at[1],load[1].at[2],status,x"


def test_the_sweep_schema_is_json_schema_of_the_example():
    jsonschema = pytest.importorskip("jsonschema")
    import tomllib
    from pathlib import Path

    from splinedeform.study.schema import json_schema

    example = Path(__file__).resolve().parents[1] / "examples" / "sweeps" / "plate_stiffness.toml"
    jsonschema.validate(tomllib.loads(example.read_text()), json_schema())
    json.dumps(json_schema())


ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


def test_the_example_sweep_shows_linear_plate_theory_on_three_models(tmp_path):
    """examples/sweeps/plate_stiffness.toml, its six cases solved in this process: twice the
    load gives twice the deflection, a stiffer plate deflects less, and at w20 = 1 the
    Navier value 0.00406235 q a⁴/D of the base scenario holds."""
    cases = plan_cases(load_sweep(ROOT / "examples" / "sweeps" / "plate_stiffness.toml"))
    assert len(cases) == 6 and len({c.model for c in cases}) == 3
    out = tmp_path / "out"
    rows = {(c.values["material.w20"], c.values["load[1].force"][2]): row
            for model in dict.fromkeys(c.model for c in cases)
            for c, row in zip([c for c in cases if c.model == model],
                              solve_group([c for c in cases if c.model == model], str(out)))}
    for w20 in (0.5, 1.0, 2.0):
        # linear statics: the same factorisation, the load doubled; rounding only (1e-12)
        assert rows[(w20, -2.0)]["p1_z"] == pytest.approx(2 * rows[(w20, -1.0)]["p1_z"],
                                                          rel=1e-12)
    assert -rows[(0.5, -1.0)]["p1_z"] > -rows[(1.0, -1.0)]["p1_z"] > -rows[(2.0, -1.0)]["p1_z"]
    # the base scenario's own check (8 cubic cells): a fraction of a per cent of Navier
    assert -rows[(1.0, -1.0)]["p1_z"] == pytest.approx(0.00406235, rel=5e-3)


def _sweep_blocks() -> list[str]:
    import re

    text = (ROOT / "docs" / "sweep.md").read_text(encoding="utf-8")
    return [b for b in re.findall(r"```toml\n(.*?)```", text, re.S) if "scenario =" in b]


@pytest.mark.parametrize("block", _sweep_blocks(), ids=lambda b: b.splitlines()[0][:30])
def test_the_sweep_files_of_the_docs_are_valid_beside_the_examples(block):
    from splinedeform.study import parse_sweep

    sweep = parse_sweep(block, source="docs/sweep.md", directory=ROOT / "examples" / "sweeps")
    assert design_points(sweep)


def test_the_docs_describe_every_key_of_sweep_files():
    from splinedeform.study import schema as S

    text = (ROOT / "docs" / "sweep.md").read_text(encoding="utf-8")
    for table, model in (("design", S.Design), ("axis", S.Axis), ("output", S.SweepOutput)):
        for name in model.model_fields:
            assert f"`{table}.{name}`" in text, f"{table}.{name} missing from docs/sweep.md"
    assert "`scenario`" in text and "`title`, `description`" in text


def test_per_case_outputs_are_written_only_when_the_sweep_asks(tmp_path):
    from sweep_files import MEMBRANE

    scenario = MEMBRANE.replace("formats = []", 'formats = ["npz"]')
    for asks in (False, True):
        text = AXES + ("\n[output]\ncases = true\n" if asks else "")
        folder = tmp_path / str(asks)
        sweep = load_sweep(write(folder, text, scenario=scenario))
        assert sweep.cases_output is asks
        case = plan_cases(sweep)[0]
        solve_group([case], str(folder / "out"), sweep.cases_output)
        written = list((folder / "out" / "cases").glob(f"{case.hash}/*.npz"))
        assert bool(written) is asks


def test_a_load_off_the_surface_fails_its_case_not_the_others_of_its_model(tmp_path):
    text = AXES.replace("values = [[0.5, 0.5], [0.3, 0.6], [0.7, 0.2]]",
                        "values = [[1.5, 0.5], [0.3, 0.6]]").replace("[0.5, 2.0]", "[0.5]")
    cases = plan_cases(load_sweep(write(tmp_path, text)))
    assert len({c.model for c in cases}) == 1
    rows = solve_group(cases, str(tmp_path / "out"))
    assert "load[1].at: u = 1.5 is outside the parameter domain" in rows[0]["status"]
    assert rows[1]["status"] == "ok"


def test_the_command_line_prints_the_sweep_schema_and_refuses_a_bad_file_with_exit_2(tmp_path):
    from typer.testing import CliRunner

    from splinedeform.cli import app

    runner = CliRunner()
    shown = runner.invoke(app, ["schema", "--sweep"])
    assert shown.exit_code == 0 and json.loads(shown.stdout)["title"] == "splinedeform sweep"
    bad = write(tmp_path, AXES.replace('key = "material.damping"', 'key = "material.colour"'))
    refused = runner.invoke(app, ["sweep", str(bad), "-o", str(tmp_path / "out")])
    assert refused.exit_code == 2
    assert "axis[1].key: axis 'material.colour' is refused" in refused.output
    assert not (tmp_path / "out").exists()       # refused before anything is written


def test_a_grid_extended_by_one_value_reuses_the_cases_computed(tmp_path):
    """Results are stored by content: the first sweep's cases are found again by the second,
    whose design puts them at other places."""
    from splinedeform.study.run import _row

    out = tmp_path / "out"
    first = plan_cases(load_sweep(write(tmp_path / "a", AXES)))
    solve_group([c for c in first if c.model == first[0].model], str(out))
    wider = AXES.replace("values = [0.5, 2.0]", "values = [0.25, 0.5, 2.0]")
    second = plan_cases(load_sweep(write(tmp_path / "a", wider)))
    found = [c for c in second if case_file(out, c.hash).exists()]
    assert [c.index for c in found] == [4, 5, 6]         # damping 0.5, now the second value
    assert [_row(c, out)["case"] for c in found] == [4, 5, 6]


def test_a_random_design_draws_log_uniformly_in_its_range_and_among_its_values(tmp_path):
    text = """\
scenario = "base.toml"
[design]
kind = "random"
n = 200
seed = 3
[[axis]]
key = "material.damping"
range = [0.1, 10.0]
scale = "log"
[[axis]]
key = "boundary.u0"
values = ["clamped", "pinned"]
"""
    points = design_points(load_sweep(write(tmp_path, text)))
    logs = np.log10([p["material.damping"] for p in points])
    assert len(points) == 200 and logs.min() >= -1.0 and logs.max() <= 1.0
    # log10 x uniform on [-1, 1]: mean 0, standard error 2/√12/√200 ≈ 0.041; 4 of them
    assert abs(logs.mean()) < 0.17
    presets = [p["boundary.u0"] for p in points]
    # each preset with chance 1/2: 100 ± 7 (binomial standard deviation); 4 of them
    assert abs(presets.count("clamped") - 100) < 28 and set(presets) == {"clamped", "pinned"}


MATERIALS = """\
scenario = "base.toml"

[[axis]]
key = "material.w10"
values = [0.5, 1.0, 3.0]

[[axis]]
key = "material.damping"
values = [0.5, 2.0]

[[axis]]
key = "material.w20"
values = [0.0, 0.01]
"""


def test_models_differing_only_in_material_share_their_geometry_and_equal_models_built_anew(
        tmp_path):
    """12 materials on one geometry: the cases after the first build their models from it
    (:mod:`splinedeform.study.geometries`). Their rows equal those of the same cases with
    every model built from scratch to 1e-12 relative: the matrices are the same weighted
    sums of the same 1-D factors (a few roundings), and a row's figures are well-conditioned
    functions of them (frequencies of separated modes, closed-form responses), so rounding
    stays near 1e-15; a wrong weight or a stale shared part would differ at O(1)."""
    from splinedeform.study import geometries

    cases = plan_cases(load_sweep(write(tmp_path, MATERIALS)))
    assert len({c.model for c in cases}) == 12 and len({c.geometry for c in cases}) == 1
    geometries.forget()
    shared = [solve_group([case], str(tmp_path / "shared"))[0] for case in cases]
    alone = []
    for case in cases:
        geometries.forget()
        alone += solve_group([case], str(tmp_path / "alone"))
    assert [r["status"] for r in shared] == ["ok"] * 12
    for a, b in zip(shared, alone):
        for key, value in b.items():
            if key in ("wall_s", "worker"):
                continue
            if isinstance(value, float):
                assert a[key] == pytest.approx(value, rel=1e-12, abs=1e-300), key
            else:
                assert a[key] == value, key
