"""What ``make demo`` and ``make test`` install, what the README says they install, and
that the demo runs with only that."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXTRAS = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]


def installed_extras(target: str) -> list[str]:
    """The extras of every ``pip install -e '.[...]'`` that ``make -n -B target`` would run."""
    if shutil.which("make") is None:
        pytest.skip("make is not installed")
    done = subprocess.run(["make", "-n", "-B", "-C", str(ROOT), target], capture_output=True,
                          text=True, check=True)
    return re.findall(r"pip install .*-e '\.\[([\w,-]+)\]'", done.stdout)


def test_make_demo_installs_the_tool_extra_and_make_test_what_the_suite_needs():
    assert installed_extras("demo") == ["tool"]
    assert installed_extras("test") == ["tool,video,cad,cad-step,sculpt,test"]


#: extras make test leaves out, and why (their tests skip with the reason)
NOT_INSTALLED_BY_MAKE_TEST = {"render3d": "VTK, large; matplotlib is the fallback",
                              "all": "everything"}


def _module(requirement: str) -> str:
    return re.split(r"[<>=\[ ]", requirement)[0].replace("-", "_").lower()


def test_make_test_installs_every_extra_whose_tests_would_otherwise_skip():
    (extras,) = installed_extras("test")
    installed = set(extras.split(","))
    assert installed | set(NOT_INSTALLED_BY_MAKE_TEST) == set(EXTRAS)
    extra_of = {_module(req): extra for extra, reqs in EXTRAS.items() if extra != "all"
                for req in reqs}
    for test in (ROOT / "tests").rglob("*.py"):
        for module in re.findall(r"importorskip\(\s*\"([\w.]+)\"", test.read_text("utf-8")):
            extra = extra_of.get(module.split(".")[0].lower())
            assert extra is None or extra in installed or extra in NOT_INSTALLED_BY_MAKE_TEST, \
                f"{test.name} skips without {module} (extra {extra!r}), which make test leaves out"


def test_readme_says_what_make_installs():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    for target in ("demo", "test"):
        line = next(line for line in readme.splitlines() if line.startswith(f"make {target} "))
        (extras,) = installed_extras(target)
        assert f"installs .[{extras}]," in line, line


def test_the_demo_runs_with_only_the_tool_extra(tmp_path):
    """Every package of the other extras refuses to import; the demo (coarser, every output
    it writes) still runs: make demo installs all it needs."""
    others = {re.split(r"[<>=\[ ]", name)[0].replace("-", "_").lower()
              for extra, names in EXTRAS.items() if extra not in ("tool", "all")
              for name in names}
    script = textwrap.dedent(f"""
        import importlib.abc, sys

        class Refuse(importlib.abc.MetaPathFinder):
            def find_spec(self, name, path, target=None):
                if name.split(".")[0].lower() in {sorted(others)!r}:
                    raise ImportError(f"{{name}} is not in the tool extra")

        sys.meta_path.insert(0, Refuse())
        from splinedeform.cli import demo_scenario
        from splinedeform.pipeline import run
        from splinedeform.scenario import with_overrides

        scenario = with_overrides(demo_scenario(), {{"solve.frames": 3, "surface.cells": [8, 4],
                                                    "output.resolution": 8}})
        result = run(scenario, {str(tmp_path / "demo")!r})
        print(sorted(path.name for _, path in result.outputs))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          env={**os.environ, "MPLBACKEND": "Agg"}, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    written = {p.name for p in (tmp_path / "demo").iterdir()}
    assert {"viewer.html", "report.json"} <= written
    assert any(name.endswith(".gif") for name in written), written
