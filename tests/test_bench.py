"""The cost study: the quick run writes its files with checked numbers; the search logic.

No timing is asserted: only what the study computes (errors against the analytic solution,
the yardstick check, the settings search on a synthetic error law, fitted slopes).
"""

import csv
import math

import numpy as np
import pytest

from splinedeform import bench
from splinedeform.errors import InputError


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    return bench.main(quick=True, outdir=out, quiet=True), out


def test_quick_run_writes_the_table_the_csv_and_the_plots(quick):
    _, out = quick
    for name in ("bench.json", "bench.md", "bench.csv", "cost_clamped.png", "cost_region.png"):
        assert (out / name).is_file(), name
    assert (out / "cost_clamped.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = (out / "bench.md").read_text()
    assert "## Family `clamped`" in text and "## Family `region`" in text
    assert "| cells | free | analytic set-up | per frame |" in text
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
    analytic = [r for r in rows if r["solver"] == "analytic"]
    assert len(analytic) == len(bench.QUICK.sizes) * len(bench.FAMILIES)
    # every analytic solution was checked against DOP853 at rtol 1e-12 on the quick nets
    for r in analytic:
        assert float(r["error"]) <= target
        assert float(r["error"]) < 1e-9
    numerical = [r for r in rows if r["solver"] != "analytic"]
    assert {r["solver"] for r in numerical} == set(bench.DEFAULT_METHODS)
    for r in numerical:
        if r["status"] == "ok":
            assert float(r["error"]) <= target
            assert math.isclose(float(r["ratio"]),
                                float(r["seconds"]) / float(next(
                                    a["seconds"] for a in analytic
                                    if (a["family"], a["cells"]) == (r["family"], r["cells"]))),
                                rel_tol=1e-4)


def test_free_counts_match_the_families(quick):
    result, _ = quick
    clamped = {r.cells: r.n_free for r in result["rows"] if r.family == "clamped"}
    assert clamped == {4: (4 + 3 - 4) ** 2, 6: (6 + 3 - 4) ** 2}     # two rows per edge fixed
    region = {r.cells: r.n_free for r in result["rows"] if r.family == "region"}
    for cells, n in region.items():
        assert n == int((~bench.region_mask(cells)).sum())


def test_numerical_error_is_measured_against_the_analytic_reference():
    """The relative error of the study, recomputed for one run, agrees with a DOP853 check."""
    t_end = bench.reference_t_end("clamped")
    case = bench.Case("clamped", 4, bench.build_model("clamped", 4), bench.study_load(t_end),
                      t_end, np.linspace(0.0, t_end, 11))
    bench.run_analytic(case)
    loose = bench.attempt(case, "dop853", 2, 60.0)          # rtol 1e-4
    tight = bench.attempt(case, "dop853", 8, 60.0)          # rtol 1e-10
    assert not loose.stopped and not tight.stopped
    assert tight.error < 1e-8 < loose.error < 1e-2


def test_search_finds_the_coarsest_level_on_a_synthetic_error_law(monkeypatch):
    """Newmark-like error 3·4^-k: the first level with error <= 1e-6 is k = 11."""
    calls = []

    def fake(case, method, level, budget, opts=None):
        calls.append(level)
        return bench.Attempt(level, 0.1 * 2**level, error=3.0 * 4.0 ** -level)

    monkeypatch.setattr(bench, "attempt", fake)
    study = bench.Study(target=1e-6)
    tried, best = bench.search(None, "newmark", 1, study)
    assert best == 11 == min(k for k in range(20) if 3.0 * 4.0 ** -k <= 1e-6)
    assert 10 in tried and tried[10].error > 1e-6                 # the coarser one was checked
    assert len(calls) <= 6


def test_search_stops_loosening_when_it_no_longer_saves_time(monkeypatch):
    """Stability-limited explicit method: every rtol reaches the target at the same cost."""
    calls = []

    def fake(case, method, level, budget, opts=None):
        calls.append(level)
        return bench.Attempt(level, 10.0, error=1e-8)

    monkeypatch.setattr(bench, "attempt", fake)
    _, best = bench.search(None, "dop853", 4, bench.Study(target=1e-6))
    assert calls == [4, 3] and best in (3, 4)


def test_search_stops_at_the_budget(monkeypatch):
    def fake(case, method, level, budget, opts=None):
        if level >= 4:
            return bench.Attempt(level, budget, stopped=True, estimate=123.0)
        return bench.Attempt(level, 1.0, error=10.0 ** -level)

    monkeypatch.setattr(bench, "attempt", fake)
    tried, best = bench.search(None, "rk45", 2, bench.Study(target=1e-8))
    assert best is None and tried[max(tried)].stopped


def test_fitted_slope_recovers_a_power_law_over_the_largest_nets():
    rows = [bench.Row("clamped", c, n, "x", "ok", seconds=2e-6 * n**1.7)
            for c, n in ((16, 225), (32, 961))]
    rows.insert(0, bench.Row("clamped", 4, 9, "x", "ok", seconds=1.0))      # overhead only
    rows.append(bench.Row("clamped", 64, 3969, "x", "over budget", seconds=30.0,
                          estimate=2e-6 * 3969**1.7))
    rows.append(bench.Row("clamped", 128, 16129, "x", "skipped", estimate=1e9))
    assert bench.fitted_slope(rows) == pytest.approx(1.7, abs=1e-12)


def test_runs_stopped_too_early_are_not_extrapolated():
    analytic = bench.Row("clamped", 32, 961, "analytic", "exact", seconds=0.5)
    case = bench.Case("clamped", 32, bench.build_model("clamped", 32), None, 1.0, np.zeros(2))
    early = {3: bench.Attempt(3, 90.0, stopped=True, estimate=9e4, progress=0.001)}
    row = bench.numerical_row(case, "bdf", early, None, analytic)
    assert row.status == "over budget" and math.isnan(row.estimate)
    assert row.ratio == pytest.approx(row.seconds / 0.5)              # a lower bound
    assert "and more" in bench._cell(row)
    later = bench.skip_row(case, "bdf", [row], 30.0, analytic)
    assert later.status == "skipped" and math.isnan(later.estimate)
    half = {3: bench.Attempt(3, 90.0, stopped=True, estimate=180.0, progress=0.5)}
    row = bench.numerical_row(case, "bdf", half, None, analytic)
    assert row.estimate == pytest.approx(180.0 + case.model.timings["assembly"])


def test_forecast_skips_after_a_run_over_budget():
    analytic = bench.Row("clamped", 32, 961, "analytic", "exact", seconds=0.5)
    history = [bench.Row("clamped", 8, 49, "rk45", "ok", seconds=1.0),
               bench.Row("clamped", 16, 225, "rk45", "over budget", seconds=30.0, estimate=16.0)]
    case = bench.Case("clamped", 32, bench.build_model("clamped", 32), None, 1.0, np.zeros(2))
    row = bench.skip_row(case, "rk45", history, 30.0, analytic)
    assert row.status == "skipped"
    power = math.log(16.0) / math.log(225 / 49)
    assert row.estimate == pytest.approx(16.0 * (961 / 225) ** power)


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
    steps = [bench.substeps(k) for k in range(2, 21)]
    ratios = np.array(steps[1:]) / np.array(steps[:-1])
    # √2 between levels up to the rounding of small integers (3/2 = 1.5, 4/3 ≈ 1.33)
    assert np.all(ratios <= 1.5 + 1e-12) and np.all(ratios >= 1.3)


def test_fastest_of_a_row_is_the_quickest_finished_run():
    rows = [bench.Row("clamped", 8, 10, "analytic", "exact", 2.0),
            bench.Row("clamped", 8, 10, "radau7", "ok", 1.0),
            bench.Row("clamped", 8, 10, "genalpha", "over budget", 0.5)]
    assert bench.fastest(rows).solver == "radau7"


def test_goal_regimes_run_and_report_their_settings():
    from splinedeform import bench_goals

    lines = []
    result = bench_goals.goals(say=lines.append, quick=True)
    assert "threads" in result["threads"] and lines[0] == result["threads"]
    for key in ("light", "load_case", "single"):
        r = result[key]
        assert r["radau7"]["status"] == "ok" and r["radau7"]["error"] <= 1e-4
        assert math.isclose(r["ratio"], r["radau7"]["seconds"] / r["analytic_s"], rel_tol=1e-12)
    assert {h["name"] for h in result["horizons"]} == {"light", "plate"}


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
    monkeypatch.setattr(bench.time, "perf_counter", lambda: float(next(ticks)))
    stopped = bench.attempt(case, "radau7", 0, budget=80)
    assert stopped.stopped
    assert 0 < stopped.progress < 0.2
    assert stopped.estimate > 5 * stopped.seconds      # extrapolated well beyond the budget
