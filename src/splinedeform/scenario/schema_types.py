"""The constants and constrained types that the scenario models of :mod:`.schema` share."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Optional, Union

from pydantic import BaseModel, ConfigDict, Field, Strict

from ..basis import KNOT_KINDS
from ..boundary import PRESETS
from ..cad_units import UNITS
from ..loads import OMEGA_MAX
from ..model import METHODS, STEP_METHODS
from ..shapes import FIT_METHODS

PROFILES = ("constant", "step", "piecewise", "harmonic")
IVP_METHODS = ("rk45", "dop853", "radau", "bdf")
MASS_MATRICES = ("consistent", "lumped")
#: length units of CAD files
CAD_UNITS = tuple(UNITS)
PHYSICS = ("parametric", "intrinsic", "shell")
#: edge kinds of the Kirchhoff–Love shell only (``physics = "shell"``)
SHELL_EDGES = ("diaphragm", "symmetry")
#: ``[material]`` keys of the shell, and those of the thin plate under tension
SHELL_KEYS = ("E", "nu", "thickness", "density")
PLATE_KEYS = ("mass", "w10", "w01", "w20", "w11", "w02", "mass_matrix")
FORMATS = ("obj", "stl", "ply", "vtu", "json", "npz", "report", "images", "gif", "mp4",
           "viewer", "3dm", "step", "iges")
#: shorthand names accepted in ``output.formats``
FORMAT_ALIASES = {"pvd": ("vtu",), "nets": ("json", "npz"), "animation": ("gif",),
                  "all": ("obj", "stl", "ply", "vtu", "json", "npz", "report", "images", "gif",
                          "viewer")}
#: latest time a scenario may ask for: beyond it the phase ω t of a vibration keeps no digits
TIME_MAX = 1e12

Real = Annotated[float, Strict(), Field(allow_inf_nan=False)]
Positive = Annotated[float, Strict(), Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Strict(), Field(ge=0, allow_inf_nan=False)]
Time = Annotated[float, Strict(), Field(ge=0, le=TIME_MAX, allow_inf_nan=False)]
Integer = Annotated[int, Strict()]
Text = Annotated[str, Strict()]
Pair = tuple[Real, Real]
Angle = Annotated[float, Strict(), Field(ge=-360, le=360, allow_inf_nan=False)]
#: index of a control point along one direction of the net (from 0)
NetIndex = Annotated[int, Strict(), Field(ge=0, le=100_000)]
Cells = Annotated[int, Strict(), Field(ge=1, le=512)]
Knots = Literal[KNOT_KINDS]  # type: ignore[valid-type]
Preset = Literal[PRESETS + SHELL_EDGES]  # type: ignore[valid-type]


class _Table(BaseModel):
    model_config = ConfigDict(extra="forbid")
