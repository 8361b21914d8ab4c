"""The cost study: the quick run writes its files with checked numbers; the search logic.

No timing is asserted: only what the study computes (errors against the analytic solution,
the yardstick check, the settings search on a synthetic error law, fitted slopes).
"""

import contextlib
import csv
import io
import math

import numpy as np
import pytest

from splinedeform import bench
from splinedeform.bench import analytic, bookkeeping, config, goals, regimes, search, tables, timing
from splinedeform.bench.bookkeeping import Row
from splinedeform.errors import InputError


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        result = bench.main(quick=True, outdir=out)
    result["printed"] = printed.getvalue()
    return result, out


def test_quick_run_prints_each_message_once(quick):
    result, _ = quick
    lines = result["printed"].splitlines()
    assert sum("BLAS threads" in line for line in lines) == 1
    assert lines[-1].startswith("written: ")


def test_quick_run_writes_the_table_the_csv_and_the_plots(quick):
    _, out = quick
    for name in ("bench.json", "bench.md", "bench.csv", "cost_clamped.png", "cost_region.png"):
        assert (out / name).is_file(), name
    assert (out / "cost_clamped.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = (out / "bench.md").read_text()
    assert "## a. Cost against net size, family `clamped`" in text
    assert "## a. Cost against net size, family `region`" in text
    assert "| cells | free | analytic (automatic modes) | modes (a-priori bound) |" in text
    assert "BLAS threads not pinned by the study" in text and "load average" in text
    assert not list(out.glob(".*tmp*"))                       # atomic writes left nothing


def test_reports_are_rendered_again_from_the_recorded_numbers(quick):
    _, out = quick
    before = (out / "bench.md").read_text(), (out / "bench.csv").read_text()
    (out / "bench.md").unlink()
    files = bench.render(out)
    assert files["markdown"].read_text() == before[0]
    assert files["csv"].read_text() == before[1]


def test_quick_run_errors_are_within_the_target(quick):
    _, out = quick
    target = bench.QUICK.target
    with open(out / "bench.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    full = [r for r in rows if r["solver"] == "analytic-all"]
    assert len(full) == len(bench.QUICK.sizes) * len(bench.FAMILIES)
    # the all-modes solution (the reference) on the smallest nets was checked against DOP853
    # at rtol 1e-12: 1e-9 leaves room for DOP853's own error, far below any target
    checked = sorted(bench.QUICK.sizes)[:bench.QUICK.yardstick_sizes]
    assert checked
    for r in full:
        if int(r["cells"]) in checked:
            assert float(r["error"]) < 1e-9, r
    automatic = [r for r in rows if r["solver"] == "analytic"]
    assert len(automatic) == len(full)
    numerical = [r for r in rows if not r["solver"].startswith("analytic")]
    assert {r["solver"] for r in numerical} == set(bench.QUICK.methods)
    for r in automatic + numerical:
        if r["status"] == "ok":
            assert float(r["error"]) <= target
    # ratios are against the fastest finished run of the same net; the CSV holds the ratio and
    # both times to 6 significant digits, each rounded by up to 5e-6 of itself, so the ratio
    # recomputed from them may differ by up to 1.5e-5 of itself (2e-5 allowed)
    for r in rows:
        line = [x for x in rows if (x["family"], x["cells"]) == (r["family"], r["cells"])
                and x["status"] in ("ok", "exact")]
        best = min(float(x["seconds"]) for x in line)
        if r["status"] in ("ok", "exact"):
            assert math.isclose(float(r["ratio"]), float(r["seconds"]) / best, rel_tol=2e-5)


def test_free_counts_match_the_families(quick):
    result, _ = quick
    clamped = {r.cells: r.n_free for r in result["rows"] if r.family == "clamped"}
    # cubic, open knots: cells + 3 control points per direction, two rows per edge fixed
    assert clamped == {c: (c + 3 - 4) ** 2 for c in bench.QUICK.sizes}
    region = {r.cells: r.n_free for r in result["rows"] if r.family == "region"}
    for cells, n in region.items():
        assert n == int((~bench.cases.region_mask(cells)).sum())


def test_numerical_error_is_measured_against_the_analytic_reference():
    """The relative error of the study, recomputed for one run, agrees with a DOP853 check."""
    t_end = bench.reference_t_end("clamped")
    case = bench.Case("clamped", 4, bench.build_model("clamped", 4), bench.study_load(t_end),
                      t_end, np.linspace(0.0, t_end, 11))
    analytic.all_modes(case)
    loose = bench.attempt(case, "dop853", 2, 60.0)          # rtol 1e-4
    tight = bench.attempt(case, "dop853", 8, 60.0)          # rtol 1e-10
    assert not loose.stopped and not tight.stopped
    assert tight.error < 1e-8 < loose.error < 1e-2


def test_search_finds_the_coarsest_level_on_a_synthetic_error_law(monkeypatch):
    """Newmark-like error 3·4^-k: the first level with error <= 1e-6 is k = 11."""
    calls = []

    def fake(case, method, level, budget, opts=None):
        calls.append(level)
        return timing.Attempt(level, 0.1 * 2**level, error=3.0 * 4.0 ** -level)

    monkeypatch.setattr(timing, "attempt", fake)
    study = bench.Study(target=1e-6)
    tried, best = search.search(None, "newmark", 1, study)
    assert best == 11 == min(k for k in range(20) if 3.0 * 4.0 ** -k <= 1e-6)
    assert 10 in tried and tried[10].error > 1e-6                 # the coarser one was checked
    assert len(calls) <= 6


def test_search_stops_loosening_when_it_no_longer_saves_time(monkeypatch):
    """Stability-limited explicit method: every rtol reaches the target at the same cost."""
    calls = []

    def fake(case, method, level, budget, opts=None):
        calls.append(level)
        return timing.Attempt(level, 10.0, error=1e-8)

    monkeypatch.setattr(timing, "attempt", fake)
    _, best = search.search(None, "dop853", 4, bench.Study(target=1e-6))
    assert calls == [4, 3] and best in (3, 4)


def test_search_stops_at_the_budget(monkeypatch):
    def fake(case, method, level, budget, opts=None):
        if level >= 4:
            return timing.Attempt(level, budget, stopped=True, estimate=123.0)
        return timing.Attempt(level, 1.0, error=10.0 ** -level)

    monkeypatch.setattr(timing, "attempt", fake)
    tried, best = search.search(None, "rk45", 2, bench.Study(target=1e-8))
    assert best is None and tried[max(tried)].stopped


def test_fitted_slope_recovers_a_power_law_over_the_largest_nets():
    rows = [Row("clamped", c, n, "x", "ok", seconds=2e-6 * n**1.7)
            for c, n in ((16, 225), (32, 961))]
    rows.insert(0, Row("clamped", 4, 9, "x", "ok", seconds=1.0))      # overhead only
    rows.append(Row("clamped", 64, 3969, "x", "over budget", seconds=30.0,
                          estimate=2e-6 * 3969**1.7))
    rows.append(Row("clamped", 128, 16129, "x", "skipped", estimate=1e9))
    assert bookkeeping.fitted_slope(rows) == pytest.approx(1.7, abs=1e-12)


def test_runs_stopped_too_early_are_not_extrapolated():
    case = bench.Case("clamped", 32, bench.build_model("clamped", 32), None, 1.0, np.zeros(2))
    early = {3: timing.Attempt(3, 90.0, stopped=True, estimate=9e4, progress=0.001)}
    row = bookkeeping.numerical_row(case, "bdf", early, None, 0.25, "")
    assert row.status == "over budget" and math.isnan(row.estimate)
    fast = Row("clamped", 32, 961, "analytic", "ok", seconds=0.5)
    bookkeeping.set_ratios([fast, row])
    assert row.ratio == pytest.approx(row.seconds / 0.5, rel=1e-12)      # a lower bound
    assert "and more" in tables.cell(row)
    later = bookkeeping.skip_row(case, "bdf", [row], 30.0)
    assert later.status == "skipped" and math.isnan(later.estimate)
    half = {3: timing.Attempt(3, 90.0, stopped=True, estimate=180.0, progress=0.5)}
    row = bookkeeping.numerical_row(case, "bdf", half, None, 0.25, "")
    assert row.estimate == pytest.approx(180.25, rel=1e-12)             # assembly added


def test_forecast_skips_after_a_run_over_budget():
    history = [Row("clamped", 8, 49, "rk45", "ok", seconds=1.0),
               Row("clamped", 16, 225, "rk45", "over budget", seconds=30.0, estimate=16.0)]
    case = bench.Case("clamped", 32, bench.build_model("clamped", 32), None, 1.0, np.zeros(2))
    row = bookkeeping.skip_row(case, "rk45", history, 30.0)
    assert row.status == "skipped"
    power = math.log(16.0) / math.log(225 / 49)
    assert row.estimate == pytest.approx(16.0 * (961 / 225) ** power, rel=1e-12)
    later = bookkeeping.skip_row(case, "rk45", history + [row], 30.0)
    assert "over the budget on the 16×16 net" in later.note          # where it was, not 32²


def _line(*runs):
    """Rows of one line from ``(solver, status, seconds, estimate, progress)``."""
    return [Row("clamped", 64, 3969, solver, status, seconds, estimate=estimate,
                progress=progress) for solver, status, seconds, estimate, progress in runs]


def test_ratios_are_against_the_fastest_run_of_each_line_only():
    nan = math.nan
    small = _line(("analytic", "ok", 2.0, nan, nan), ("radau7", "ok", 8.0, nan, nan))
    big = [Row("clamped", 128, 16129, "analytic", "ok", 30.0),
           Row("clamped", 128, 16129, "analytic-all", "not run", estimate=900.0),
           Row("clamped", 128, 16129, "radau7", "ok", 20.0)]
    bookkeeping.set_ratios(small + big)
    assert [r.ratio for r in small] == pytest.approx([1.0, 4.0], rel=1e-12)
    # 128²: the integrator is fastest; the forecast of a row not run is a ratio too
    assert [r.ratio for r in big] == pytest.approx([1.5, 45.0, 1.0], rel=1e-12)
    assert tables.verdict(big) == ("Radau IIA-7", "**we lose** ×1.5")
    assert tables.verdict(small) == ("analytic (automatic modes)", "wins, ×4 ahead")
    assert "not run, ≈900 s forecast" in tables.cell(big[1])


def test_a_lead_over_forecasts_only_is_marked_as_a_forecast():
    line = [Row("clamped", 128, 16129, "analytic", "ok", 20.0),
            Row("clamped", 128, 16129, "radau7", "skipped", estimate=200.0)]
    assert tables.verdict(line)[1] == "wins, ≈×10 ahead (forecast)"
    line.append(Row("clamped", 128, 16129, "radau3", "ok", 100.0))
    assert tables.verdict(line)[1] == "wins, ×5 ahead"                  # measured beats forecast


def test_a_stopped_run_that_extrapolates_below_every_finished_run_is_the_fastest():
    nan = math.nan
    line = _line(("analytic", "ok", 10.0, nan, nan), ("radau7", "over budget", 30.0, 6.0, 0.5),
                 ("genalpha", "over budget", 30.0, 1.0, 0.01))      # too early: ignored
    name, fares = tables.verdict(line)
    assert name == "Radau IIA-7 (extrapolated)" and fares == "**we lose** ×1.67"
    value, analytic_row, integrator, extrapolated = goals.ratio(line)
    assert value == pytest.approx(0.6, rel=1e-12) and extrapolated
    assert analytic_row.solver == "analytic" and integrator.solver == "radau7"


def test_goals_read_the_analytic_row_they_name_and_the_fastest_integrator():
    """The net-size goals compare the default call (issue 25), the others the faster of
    the two analytic rows."""
    nan = math.nan
    rows = [Row("clamped", 32, 961, s, st, t, regime="size") for s, st, t in
            (("analytic", "ok", 0.5), ("analytic-all", "exact", 0.25), ("radau7", "ok", 1.0),
             ("radau3", "ok", 2.0))]
    rows += [Row("clamped", 32, 961, "analytic", "ok", 0.1, regime="load case",
                 case="each additional load case"),
             Row("clamped", 32, 961, "radau7", "ok", 3.0, regime="load case",
                 case="each additional load case")]
    found = {g.name.split(",")[0]: g for g in goals.issue_goals(rows, 200, 1e-6)}
    plate = found["bench plate 32²"]
    assert plate.met is False and plate.measured.startswith("×2:")      # 1.0 / 0.5 < ×5
    assert plate.target == "≥ ×5"
    assert found["each additional load case on a solved model"].met is True   # ×30
    assert found["bench plate 64²"].met is None and "not measured" in found["bench plate 64²"].measured
    assert math.isnan(goals.ratio([])[0]) and nan != nan


def test_the_all_modes_forecast_follows_the_growth_of_the_two_largest_nets():
    smaller = [Row("clamped", c, n, "analytic-all", "exact", t) for c, n, t in
               ((16, 225, 0.04), (32, 961, 0.3), (64, 3969, 12.0))]
    case = bench.Case("clamped", 128, bench.build_model("clamped", 12), None, 1.0, np.zeros(2))
    row = analytic.not_run(case, smaller)
    n = case.model.n_free
    p = math.log(12.0 / 0.3) / math.log(3969 / 961)
    assert row.status == "not run" and math.isnan(row.seconds)
    assert row.estimate == pytest.approx(12.0 * (n / 3969) ** p, rel=1e-12)
    assert f"n_free^{p:.2f}" in row.note


def test_automatic_settings_say_modes_and_bound_or_all_modes():
    assert analytic.automatic_label(1e-6, 256, 2.1e-7, 3969) == \
        "tolerance 1e-06: 256 modes, bound 2.1e-07"
    assert "all modes" in analytic.automatic_label(1e-6, 0, math.nan, 9)
    assert "all modes" in analytic.automatic_label(1e-6, 9, 0.0, 9)


def test_a_deadline_profile_stops_a_run_and_keeps_the_load_otherwise():
    from splinedeform import loads

    load = bench.study_load(2.0)
    wrapped, clocks = timing.timed_load(load, deadline=math.inf)
    term = wrapped.terms()[0]
    t = np.linspace(0.0, 2.0, 9)
    # delegated, no arithmetic of its own: equal to one rounding of the profile's values
    np.testing.assert_allclose(term.profile(t), load.profile(t), rtol=1e-15, atol=0)
    assert term.profile.jumps() == load.profile.jumps()
    assert clocks[0].reached == 2.0
    stopped, _ = timing.timed_load(load + loads.Point(0.5, 0.5, (0, 0, 1)), deadline=-math.inf)
    assert len(stopped.terms()) == 2
    with pytest.raises(timing.OverBudget):
        stopped.terms()[1].profile(0.0)


def test_a_study_is_rebuilt_from_its_record():
    study = config.make_study(sizes=[32, 8, 8], budget=12.0, methods=["radau7"])
    assert study.sizes == (8, 32) and study.budget == 12.0
    assert study.budget_for(64) == 12.0 and study.budget_for(128) == study.large_budget
    from dataclasses import asdict
    record = {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(study).items()}
    record["retired_setting"] = 1                                       # older records
    assert config.from_record(record) == study


@pytest.mark.parametrize("kwargs, words", [
    ({"sizes": [4, 1]}, "sizes"),
    ({"methods": ["euler"]}, "unknown numerical method"),
    ({"families": ["dome"]}, "unknown problem family"),
    ({"budget": 0}, "budget"),
    ({"target": 2.0}, "target"),
])
def test_bad_settings_are_refused(kwargs, words, tmp_path):
    with pytest.raises(InputError, match=words):
        bench.main(outdir=tmp_path, quiet=True, **kwargs)


def test_substep_levels_are_a_factor_sqrt2_apart():
    steps = [search.substeps(k) for k in range(2, 21)]
    ratios = np.array(steps[1:]) / np.array(steps[:-1])
    # √2 between levels up to the rounding of small integers (3/2 = 1.5, 4/3 ≈ 1.33)
    assert np.all(ratios <= 1.5 + 1e-12) and np.all(ratios >= 1.3)


def test_fastest_of_a_row_is_the_quickest_finished_run():
    rows = [Row("clamped", 8, 10, "analytic", "exact", 2.0),
            Row("clamped", 8, 10, "radau7", "ok", 1.0),
            Row("clamped", 8, 10, "genalpha", "over budget", 0.5)]
    assert bookkeeping.fastest(rows).solver == "radau7"


def test_regimes_run_and_report_their_lines():
    lines = []
    rows = regimes.run(config.QUICK, say=lines.append, quick=True)
    found = {(r.regime, r.case) for r in rows}
    assert {regime for regime, _ in found} == {"horizon", "load case", "one state", "probes"}
    assert ("horizon", "heavy damping, 3 periods") in found
    assert ("horizon", "light damping, 1 period") in found
    assert ("probes", "5 probes") in found and ("probes", "whole control nets") in found
    # one state asks dynamic for its one time (modes chosen for it)
    state = [r for r in rows if r.regime == "one state" and r.solver == "analytic"]
    assert state and state[0].setting.startswith("default call, times given")
    for r in rows:
        if r.status == "ok":
            assert r.error <= config.QUICK.target
    bookkeeping.set_ratios(rows)
    for line in {r.line for r in rows}:
        here = [r for r in rows if r.line == line and r.status in ("ok", "exact")]
        assert min(r.ratio for r in here) == 1.0                        # the fastest itself
    assert lines and all(isinstance(x, str) for x in lines)


def test_a_run_stopped_at_the_budget_reports_where_its_stepping_was(monkeypatch):
    """Before stepping, the integrators probe the load up to 97 % of t_end (which coordinates
    move); the progress of a stopped run must be that of the stepping, not of the probes.
    A fake clock ticking once per reading stops the run after a few dozen load calls, far
    from the end: the old bookkeeping reported 97 % here and extrapolated ~budget/0.97."""
    import itertools

    t_end = bench.reference_t_end("clamped")
    times = np.linspace(0.0, t_end, 200)
    case = bench.Case("clamped", 4, bench.build_model("clamped", 4), bench.study_load(t_end),
                      t_end, times)
    ticks = itertools.count()
    monkeypatch.setattr(timing.time, "perf_counter", lambda: float(next(ticks)))
    stopped = bench.attempt(case, "radau7", 0, budget=80)
    assert stopped.stopped
    assert 0 < stopped.progress < 0.2
    assert stopped.estimate > 5 * stopped.seconds      # extrapolated well beyond the budget


def test_beyond_the_dense_limit_all_modes_are_forecast_and_the_reference_cross_checked(
        monkeypatch):
    """With the dense limit set below a 6×6 net: its all-modes row is not run (a forecast
    from the 4×4 and 5×5 nets, never a time), the reference is the automatic mode count at a
    tighter tolerance, and an independent Radau IIA-7 run agrees with it over the switch-on;
    only the integrator fastest on the previous net runs there."""
    from splinedeform.bench import sweep

    monkeypatch.setattr(analytic, "DENSE_LIMIT", 20)                 # 4²: 9, 5²: 16, 6²: 25
    monkeypatch.setattr(sweep, "LARGE", 5)
    study = config.make_study(sizes=[4, 5, 6], quick=True, methods=["radau7", "radau3"],
                              families=["clamped"])
    rows = sweep.study_family("clamped", study, lambda s: None)
    big = {r.solver: r for r in rows if r.cells == 6}
    assert big["analytic-all"].status == "not run" and math.isnan(big["analytic-all"].seconds)
    assert big["analytic-all"].estimate > 0
    assert "automatic mode count" in big["analytic"].note
    difference = float(big["analytic"].note.split("differs from it by ")[1].split(" ")[0])
    assert difference < study.target                # an independent method agrees with it
    assert big["analytic"].error <= study.target
    skipped = [r for r in big.values() if r.status == "skipped"]
    assert len(skipped) == 1 and "only the fastest integrator" in skipped[0].note


def test_search_does_not_try_a_level_known_to_miss(monkeypatch):
    """Radau-like error 1e-3·√2^(-13k): level 2 passes 1e-6, level 1 misses by ×11; with
    the floor at 1 (it missed by more than ten times on the previous net) it is not run."""
    calls = []

    def fake(case, method, level, budget, opts=None):
        calls.append(level)
        return timing.Attempt(level, 1.0 + level, error=1e-3 * math.sqrt(2.0) ** (-13 * level))

    monkeypatch.setattr(timing, "attempt", fake)
    limits = bench.Study(target=1e-6)
    _, best = search.search(None, "radau7", 2, limits, floor=1)
    assert best == 2 and calls == [2]
    calls.clear()
    _, best = search.search(None, "radau7", 2, limits)
    assert best == 2 and calls == [2, 1]


def test_a_net_too_large_for_memory_is_refused_by_its_estimate(tmp_path):
    # 100000² cells: 1.0e10 control points x (24 + 3 x 49 x 12) bytes = 1.6e4 TiB, refused
    # before anything is allocated (it used to ask numpy for a 74.5 GiB array)
    from typer.testing import CliRunner

    from splinedeform import cli
    from splinedeform.budget import net_memory

    assert net_memory(100_000, 100_000) == pytest.approx(100_003**2 * 1788.0, rel=1e-12)
    result = CliRunner().invoke(cli.app, ["bench", "--sizes", "8,100000", "-q",
                                          "-o", str(tmp_path / "b")])
    assert result.exit_code == 2, result.output
    assert "sizes [100000]: a 100000 x 100000-cell net needs about" in result.output
    assert "more than the 4 GiB" in result.output and "internal error" not in result.output
    assert not (tmp_path / "b").exists()


def test_the_dop853_check_runs_on_small_nets_only(monkeypatch):
    """The all-modes solution is checked against DOP853 on the smallest nets, and only up to
    YARDSTICK_CELLS cells per direction (beyond, the check alone outlasts the study's
    budget several times: at 32² it had not finished after 480 s)."""
    from dataclasses import replace

    from splinedeform.bench import sweep

    checked = []
    monkeypatch.setattr(sweep, "YARDSTICK_CELLS", 3)
    monkeypatch.setattr(sweep, "yardstick", lambda case, row, budget: checked.append(case.cells))
    study = config.make_study(sizes=[3, 4], quick=True, methods=["radau7"],
                              families=["clamped"])
    study = replace(study, yardstick_sizes=2)
    sweep.study_family("clamped", study, lambda text: None)
    assert checked == [3]
    assert config.YARDSTICK_CELLS == 16
