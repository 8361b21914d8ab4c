"""One model for every physics: the plate and the shell behind :class:`Formulation`.

The plate under tension (one surface, a body) and the Kirchhoff–Love shell give the model
the same interface, and static, modes and dynamics are the model's only; what the shell
gains by it (the model's mode count to a tolerance) is checked against all its modes.
"""

from pathlib import Path

import numpy as np
import pytest

import splinedeform as sd
import splinedeform.physics
from splinedeform.physics.formulation import Formulation
from splinedeform.physics.plate import PlateFormulation
from splinedeform.physics.shell_formulation import ShellFormulation
from splinedeform.physics.shell_model import AreaForce, ShellModel

from test_layers import imported_modules

PHYSICS = Path(splinedeform.physics.__file__).parent
FORMULATIONS = [PHYSICS / f"{name}.py" for name in ("formulation", "plate", "shell_formulation")]
PINNED = {e: "pinned" for e in ("u0", "u1", "v0", "v1")}


def models():
    plane = sd.shapes.plane(cells=4)
    right = plane.with_control_points(plane.control_points + [1.0, 0.0, 0.0])
    return [sd.Model(plane, sd.Material(w10=1, w01=1), "clamped"),
            sd.Model(plane, sd.Material(w10=1, w01=1), "clamped", physics="intrinsic"),
            sd.BodyModel(sd.Body([plane, right]), sd.Material(w10=1, w01=1), "clamped"),
            ShellModel(plane, sd.ShellMaterial(1e4, 0.3, 0.01), PINNED),
            ShellModel(sd.Body([plane, right]), sd.ShellMaterial(1e4, 0.3, 0.01), "pinned")]


@pytest.mark.parametrize("model", models(), ids=["plate", "intrinsic", "plate body", "shell",
                                                 "shell body"])
def test_every_model_is_the_one_model_with_a_formulation(model):
    assert isinstance(model, sd.Model)
    assert isinstance(model.formulation, Formulation)
    assert isinstance(model.formulation, (PlateFormulation, ShellFormulation))
    assert model.T.shape[0] == model.formulation.per_point * sum(
        s.shape[0] * s.shape[1] for s in (model.patches or [model.surface]))


@pytest.mark.parametrize("name", ["static", "eigen", "modes", "frequencies", "dynamic",
                                  "load_vector", "modal_basis", "initial_state"])
def test_the_constructors_repeat_none_of_the_models_solves(name):
    for cls in (sd.BodyModel, ShellModel):
        assert name not in vars(cls), f"{cls.__name__} redefines {name}"


@pytest.mark.parametrize("path", FORMULATIONS, ids=lambda p: p.name)
def test_no_formulation_imports_a_model(path):
    offending = sorted(n for n in imported_modules(path.read_text(), path)
                       if n.split(".")[:2] == ["splinedeform", "model"]
                       or n.startswith(("splinedeform.body.model",
                                        "splinedeform.physics.shell_model")))
    assert not offending, f"{path.name} imports {offending}"


def test_the_shell_takes_the_models_mode_count_to_a_tolerance():
    """Above 1024 unknowns the model chooses the fewest modes (plus the static part of the
    rest) whose a-priori bound meets ``tolerance``; measured against all modes."""
    plate = sd.shapes.plane(cells=18)
    model = ShellModel(plate, sd.ShellMaterial(1e4, 0.3, 0.01), PINNED)
    assert model.n_free > 1024
    load = AreaForce(force=(0.0, 0.0, 1.0))
    omega1 = model.frequencies(1)[0]
    t = np.linspace(0.0, 6 * np.pi / omega1, 13)
    chosen = model.dynamic(load, t[-1], tolerance=1e-4, times=t)
    assert chosen.truncation["modes"] < model.n_free / 2      # measured: 381 of 1083
    every = model.dynamic(load, t[-1], modes="all")
    moved = every.control_points(t) - plate.control_points
    error = np.abs(chosen.control_points(t) - every.control_points(t)).max()
    # the bound: the largest control-point coordinate's error at most the tolerance of the
    # largest displacement on [0, t_end] (measured 4.2e-6 of it; the all-modes solution's
    # round-off is ~1e-12 of it)
    assert error <= 1e-4 * np.abs(moved).max()
