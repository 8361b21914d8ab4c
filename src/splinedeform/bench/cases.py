"""The problems of the cost study: models, loads, frame times and the error measure.

Families (cubic B-splines, open knots, unit square, ``μ = 1``):

``clamped``
    A clamped square plate under tension: ``w10 = w01 = 10``, ``w20 = w11 = w02 = 1``,
    viscous damping ``γ = 0.8`` and Rayleigh ``β = 5·10⁻⁴``, i.e. modal damping
    ``c_i = γ + β λ_i``: 2 % in the lowest mode, under-damped up to about 100 ω₁.
``region``
    The same plate with only the control points of a central disc (radius 0.35, by their
    Greville abscissae) moving: a free region that is not a rectangle (general eigen-solution).

Load: a point force ``(0, 0, -1)`` at ``(u, v) = (0.4, 0.3)``, on at ``t = 0`` and off at
``t_end/2``; ``t_end`` is ten periods of the lowest mode of a 16×16 net of the family. The
error of a run is ``max |p - p_ref| / max |p_ref - p_rest|`` over all frames, control points
and coordinates.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from .. import loads
from ..errors import InputError
from ..material import Material
from ..model import Model
from ..shapes import plane

Array = NDArray[np.float64]
FAMILIES = ("clamped", "region")
PLATE = Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0, w11=1.0,
                 w02=1.0)
SEPARABLE_PLATE = replace(PLATE, w11=0.0)
LIGHT = replace(PLATE, damping=0.05, rayleigh=0.0)
"""Light damping: ``γ = 0.05``, ``β = 0`` (about 0.1 % of critical in the lowest mode)."""
HEAVY = replace(PLATE, damping=8.0)
"""Heavy damping: ``γ = 8`` with the plate's ``β`` (about 20 % of critical in the lowest
mode, the high modes over-damped)."""
FORCE_AT = (0.4, 0.3)
REGION_RADIUS = 0.35


def region_mask(cells: int) -> NDArray[np.bool_]:
    """Fixed control points: those whose Greville point lies outside the central disc."""
    g = plane(cells=(cells, cells)).basis_u.greville()
    return (g[:, None] - 0.5) ** 2 + (g[None, :] - 0.5) ** 2 > REGION_RADIUS**2


def build_model(family: str, cells: int, material: Material = PLATE) -> Model:
    """The model of a family on an ``cells × cells`` net (assembled on construction)."""
    surface = plane(cells=(cells, cells))
    if family == "clamped":
        return Model(surface, material, boundary="clamped")
    if family == "region":
        return Model(surface, material, boundary="free", fixed=region_mask(cells))
    raise InputError(f"unknown problem family {family!r}; choose one of {FAMILIES}")


def study_load(t_end: float, profile: loads.Profile | None = None) -> loads.Load:
    """Point force ``(0, 0, -1)`` at :data:`FORCE_AT`, on at ``t = 0``, off at ``t_end / 2``."""
    return loads.Point(*FORCE_AT, (0.0, 0.0, -1.0),
                       profile=profile or loads.Step(0.0, 0.5 * t_end))


@functools.lru_cache(maxsize=None)
def lowest_period(family: str, cells: int = 16, material: Material = PLATE) -> float:
    """``2π / ω₁`` of a net of the family."""
    omega = build_model(family, cells, material).frequencies(1)[0]
    return 2 * math.pi / float(omega)


def reference_t_end(family: str) -> float:
    """Ten periods of the lowest mode of a 16×16 net of the family."""
    return 10 * lowest_period(family)


@dataclass
class Case:
    """A model, its load and frame times, with the reference nets once computed.

    ``reference`` holds the nets every run is compared with (``(F, n_u, n_v, 3)``),
    ``scale`` is ``max |reference - rest|``, ``reference_note`` says how it was obtained.
    """

    family: str
    cells: int
    model: Model
    load: loads.Load
    t_end: float
    times: Array
    reference: Array = field(default_factory=lambda: np.zeros(0))
    scale: float = 1.0
    material: Material = PLATE
    reference_note: str = ""

    def fresh_model(self) -> Model:
        """A newly built model of the case (nothing cached from earlier solves)."""
        return build_model(self.family, self.cells, self.material)

    def set_reference(self, nets: Array, note: str) -> None:
        """Keep ``nets`` as the reference and its scale ``max |nets - rest|``."""
        self.reference = np.asarray(nets)
        self.scale = float(np.abs(self.reference - self.model.surface.control_points).max())
        self.reference_note = note


def make_case(family: str, cells: int, frames: int, t_end: float | None = None,
              material: Material = PLATE, load: loads.Load | None = None) -> Case:
    """A case of ``frames`` evenly spaced frames on ``[0, t_end]`` (default ten periods)."""
    t_end = reference_t_end(family) if t_end is None else t_end
    times = np.linspace(0.0, t_end, frames)
    return Case(family, cells, build_model(family, cells, material),
                load or study_load(t_end), t_end, times, material=material)


def relative_error(nets: Array, case: Case) -> float:
    """``max |p - p_ref| / max |p_ref - p_rest|`` over frames, control points, coordinates."""
    err = float(np.abs(np.asarray(nets) - case.reference).max()) / case.scale
    return err if math.isfinite(err) else math.inf
