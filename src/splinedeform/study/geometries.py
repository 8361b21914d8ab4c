"""Models of one geometry on a worker: cases that differ only in their material's weights.

``K_r = Σ w_ab (T_uᵀ G_a^u T_u) ⊗ (T_vᵀ G_b^v T_v)`` and ``M_r = μ (T_uᵀ G_0^u T_u) ⊗
(T_vᵀ G_0^v T_v)`` (DESIGN.md §1.5): the surface, the constraints and the reduced 1-D Gram
matrices depend on ``[surface]``, ``[boundary]`` and the material's other keys (mass
matrix, physics), not on the weights ``mass``, ``damping``, ``rayleigh``, ``w10`` … ``w02``.
Each worker keeps a model of each geometry it has built (:attr:`.cases.Case.geometry`,
the :data:`GEOMETRIES` most recent; a copy without modal basis), and the model of a case
of a geometry already seen is :meth:`~splinedeform.Model.with_material` of it: the case's
own work is the weighted sums and its eigen-solution. Models whose geometry is not shared
(:attr:`~splinedeform.Model.shares_geometry` false: trimmed, intrinsic, rational weights,
coupled C0 lines, shells, bodies) are built anew.
"""

from __future__ import annotations

from collections import OrderedDict

from ..material import Material
from ..model import Model
from ..scenario import Built
from ..scenario.body import check_single_surface_loads
from ..scenario.build import _located, build_model
from .cases import Case

#: geometries a worker keeps (each holds one model: its surface, constraints and factors)
GEOMETRIES = 8

_seen: OrderedDict[str, Built] = OrderedDict()


def model_of(case: Case) -> Built:
    """The surface and model of ``case`` (``load = None``), from the model of its geometry
    when this process has built one; raises what :func:`~.scenario.build.build_model`
    raises, with the same keys."""
    scenario = case.scenario
    assert scenario is not None
    seen = _seen.get(case.geometry) if case.geometry else None
    if seen is None:
        built = build_model(scenario)
    else:
        check_single_surface_loads(scenario, scenario.surface.parameters.get("face")
                                   if scenario.surface.shape == "cad" else None)
        with _located(scenario, "material"):
            material = Material(**scenario.material.weights())
        with _located(scenario, "boundary"):
            model = seen.model.with_material(material)
        built = Built(surface=seen.surface, model=model, load=None, fixed=seen.fixed,
                      units=seen.units)
    model = built.model
    if seen is not None:
        _seen.move_to_end(case.geometry)
    elif case.geometry and type(model) is Model and model.shares_geometry:
        # kept: a copy without the case's modal basis and other caches (a few sparse
        # matrices), not the case's model, whose eigenvectors may be large
        _seen[case.geometry] = Built(surface=built.surface,
                                     model=model.with_material(model.material), load=None,
                                     fixed=built.fixed, units=built.units)
        _seen.move_to_end(case.geometry)
        while len(_seen) > GEOMETRIES:
            _seen.popitem(last=False)
    return built


def forget() -> None:
    """Drop the models kept (the next case of every geometry is built from scratch)."""
    _seen.clear()
