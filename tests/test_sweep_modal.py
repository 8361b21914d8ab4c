"""Load cases read out from modal coordinates (study/modal_cases.py) against pipeline runs.

One clamped membrane, two loads (a point force switched on and off, a uniform force
``sin(Ωt + φ)``), three places of the point, each solved in closed form and with Newmark:
the analytic cases of the model are read out together from their modal coordinates, the
Newmark ones go through the pipeline; every row equals the figures of ``pipeline.run``.
"""

from __future__ import annotations

import numpy as np

from splinedeform.pipeline import run
from splinedeform.scenario import parse_scenario
from splinedeform.scenario.build import build_model
from splinedeform.study.cases import plan_cases
from splinedeform.study.measure import figures
from splinedeform.study.modal_cases import prepare
from splinedeform.study.read import load_sweep
from splinedeform.study.solve import solve_group

from sweep_files import MEMBRANE, write

TWO_LOADS = MEMBRANE.replace('profile = "step"\n', """profile = "step"
t_on = 0.2
t_off = 1.1

[[load]]
kind = "uniform"
force = [0.1, 0.0, 0.4]
profile = "harmonic"
omega = 3.0
phase = 0.4
""")
PLACES = [[0.5, 0.5], [0.3, 0.6], [0.7, 0.2]]
SWEEP = f"""\
scenario = "base.toml"

[[axis]]
key = "solve.method"
values = ["analytic", "newmark"]

[[axis]]
key = "load[1].at"
values = {PLACES}
"""


def test_modal_read_out_equals_the_pipeline_for_every_case(tmp_path):
    cases = plan_cases(load_sweep(write(tmp_path, SWEEP, scenario=TWO_LOADS)))
    assert len({c.model for c in cases}) == 1 and len(cases) == 6
    shared = build_model(cases[0].scenario)
    modal = [prepare(c.scenario, shared, False) is not None for c in cases]
    assert modal == [True] * 3 + [False] * 3          # analytic read out, Newmark not
    rows = solve_group(cases, str(tmp_path / "out"))
    assert [row["status"] for row in rows] == ["ok"] * 6
    for case, row in zip(cases, rows):
        method, (u, v) = case.values["solve.method"], case.values["load[1].at"]
        text = TWO_LOADS.replace("at = [0.5, 0.5]", f"at = [{u}, {v}]") \
                        .replace('kind = "dynamic"', f'kind = "dynamic"\nmethod = "{method}"')
        expected = figures(run(parse_scenario(text, source="alone.toml")))
        assert set(expected) <= set(row)
        # the same closed form on the same modes, d = Φq read out through Φᵀ M Φ = I and
        # Φᵀ K Φ = Λ instead of M and K: equal up to the rounding of the ~30-mode
        # eigensolve and of reordered sums (~1e-15 each), hence 1e-12 of each energy and
        # of the largest displacement for displacements
        scale = abs(expected["max_displacement"])
        for name, value in expected.items():
            tol = 1e-12 * (abs(value) if name.startswith(("omega", "kinetic", "strain",
                                                          "total")) else scale)
            assert abs(row[name] - value) <= tol, (case.index, name, row[name], value)
    # the harmonic load moves x too: the probes' x differ from 0 in every case
    assert all(abs(row["p1_x"]) > 0 for row in rows)
    assert np.isfinite([row["total_energy_end"] for row in rows]).all()


def test_models_of_few_cases_travel_several_to_a_task_in_design_order(tmp_path):
    from splinedeform.study.run import TASKS_PER_WORKER, tasks

    text = 'scenario = "base.toml"\n[[axis]]\nkey = "material.w10"\nrange = [1.0, 4.0]\n' \
           'count = 50\n'
    groups = [[c] for c in plan_cases(load_sweep(write(tmp_path, text)))]
    packed = tasks(groups, workers=2)
    size = -(-50 // (TASKS_PER_WORKER * 2))       # ⌈50 / 16⌉ = 4 cases a task
    assert [len(task) for task in packed] == [size] * (50 // size) + [50 % size]
    assert [g[0].index for task in packed for g in task] == list(range(1, 51))
    # a model of many cases is a task of its own, the singles around it packed
    big = [case for g in groups[:20] for case in g]
    assert [len(t) for t in tasks([big] + groups[20:], workers=2)] == \
        [1] + [size] * 7 + [30 - 7 * size]
