"""The solver layer is a layer: modules under ``splinedeform/solvers/`` never import the model.

The solvers take matrices (or their Kronecker factors), forcing and times and return
coefficients; the model gathers what they need and dispatches to them. Checked on the
source by parsing every import statement (top level, inside functions and under
``TYPE_CHECKING`` alike) with :mod:`ast`, so a lazy or type-only import counts too.
"""

import ast
from pathlib import Path

import pytest

import splinedeform
import splinedeform.solvers

PACKAGE = Path(splinedeform.__file__).parent
SOLVERS = sorted(Path(splinedeform.solvers.__file__).parent.glob("*.py"))
ABOVE = {"model", "solution", "cli", "pipeline", "scenario", "export", "modal_solve",
         "spectrum", "bench", "bench_goals", "sculpt", "outputs", "budget", "body", "readout", "modal_solution"}
"""Modules of the layers above the solvers (``splinedeform.<name>`` and below it)."""


def imported_modules(source: str, path: Path) -> set[str]:
    """Absolute names of every module the text ``source`` of the file ``path`` imports
    (relative imports resolved against ``path``'s package)."""
    package = ["splinedeform"] + list(path.parent.relative_to(PACKAGE).parts)
    names = set()
    for node in ast.walk(ast.parse(source, str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            names.add(module)
            names.update(f"{module}.{alias.name}" for alias in node.names)
    return names


def above(name: str) -> bool:
    parts = name.split(".")
    return len(parts) > 1 and parts[0] == "splinedeform" and parts[1] in ABOVE


def test_the_solver_modules_are_found():
    names = {p.stem for p in SOLVERS}
    assert {"numeric", "modal_basis", "rigid", "kronecker_eigen", "analytic"} <= names


@pytest.mark.parametrize("path", SOLVERS, ids=lambda p: p.name)
def test_no_solver_imports_the_layers_above(path):
    offending = sorted(n for n in imported_modules(path.read_text(), path) if above(n))
    assert not offending, f"{path.name} imports {offending}"


def test_the_check_sees_relative_lazy_and_type_only_imports():
    """A type-only relative import, a lazy one and an absolute one are all caught."""
    source = ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from ..model import Model\n"
              "def f():\n    from .. import solution\n    import splinedeform.cli\n"
              "    from ..loads import Step\n")
    names = imported_modules(source, PACKAGE / "solvers" / "numeric.py")
    assert {n.split(".")[1] for n in names if above(n)} == {"model", "solution", "cli"}


def test_solutions_do_not_import_the_model():
    """``solution.py`` reads out coefficients with a :class:`~splinedeform.solution.Readout`;
    it imports nothing of the model or of its dispatch."""
    path = PACKAGE / "solution.py"
    names = imported_modules(path.read_text(), path)
    dispatch = {"model", "modal_solve", "spectrum"}
    assert not {n for n in names if n.startswith("splinedeform.") and n.split(".")[1] in dispatch}


def test_a_solution_holds_its_readout_not_the_model():
    import numpy as np

    import splinedeform as sd

    model = sd.Model(sd.shapes.plane(cells=(4, 4)), sd.Material(w10=1, w01=1),
                     boundary="clamped")
    load = sd.Uniform((0.0, 0.0, -1.0))
    for sol in (model.static(load), model.dynamic(load, 1.0),
                model.dynamic(load, 1.0, method="newmark", times=np.linspace(0, 1, 3))):
        assert not hasattr(sol, "model")
        assert isinstance(sol.readout, sd.solution.Readout)
