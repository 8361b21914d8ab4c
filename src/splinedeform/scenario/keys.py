"""The documented keys of a scenario file: checker, default and meaning of each."""

from __future__ import annotations

import math

from ..basis import KNOT_KINDS as KNOTS
from ..boundary import EDGES, PRESETS
from ..model import METHODS, STEP_METHODS
from ..shapes import FIT_METHODS
from .checks import Key, array_of, choice, integer, number, one_or_pair, scalar_or_pair, text, vector

SHAPES = ("plane", "tile", "half_sphere", "cylinder", "torus", "saddle", "file")
LOAD_KINDS = ("point", "uniform", "pressure")
PROFILES = ("constant", "step", "piecewise", "harmonic")
SOLVE_KINDS = ("static", "modes", "dynamic")
IVP_METHODS = ("rk45", "dop853", "radau", "bdf")
MASS_MATRICES = ("consistent", "lumped")
FORMATS = ("obj", "stl", "ply", "vtu", "json", "npz", "report", "images", "gif", "mp4",
           "viewer")
#: shorthand names accepted in ``output.formats``
FORMAT_ALIASES = {"pvd": ("vtu",), "nets": ("json", "npz"), "animation": ("gif",),
                  "all": ("obj", "stl", "ply", "vtu", "json", "npz", "report", "images", "gif",
                          "viewer")}



_POSITIVE = number(0.0, open_low=True)
#: latest time a scenario may ask for: beyond it the phase ω t of a vibration keeps no digits
TIME_MAX = 1e12
_TIME = number(0.0, TIME_MAX, open_low=True)
_TIME0 = number(0.0, TIME_MAX)
_NONNEG = number(0.0)
_REAL = number()
_PAIR = vector(2, _POSITIVE, "[u, v]")
_RANGE = vector(2, _REAL, "[low, high]")

#: parameters of each built-in shape (passed to the function of ``splinedeform.shapes``)
_SIZE = Key(scalar_or_pair(_POSITIVE, "[L_u, L_v]"), (1.0, 1.0),
            "side lengths; the domain is [0, L_u] × [0, L_v]")
SHAPE_PARAMETERS: dict[str, dict[str, Key]] = {
    "plane": {"size": _SIZE},
    "tile": {"radius": Key(_POSITIVE, 1.0, "radius of the arc"),
             "angle": Key(number(0.0, 2 * math.pi, open_low=True), math.pi / 2,
                          "opening angle of the arc (radians, < 2π)"),
             "length": Key(_POSITIVE, 2.0, "length along the axis")},
    "half_sphere": {"radius": Key(_POSITIVE, 1.0, "sphere radius")},
    "cylinder": {"radius": Key(_POSITIVE, 1.0, "radius"),
                 "height": Key(_POSITIVE, 2.0, "height (along z)")},
    "torus": {"R": Key(_POSITIVE, 1.0, "radius of the centre line"),
              "r": Key(_POSITIVE, 0.4, "tube radius (r < R)")},
    "saddle": {"size": _SIZE,
               "height": Key(_REAL, 0.25, "z = height (ξ² - η²), ξ, η in [-1, 1]")},
    "file": {},
}

SURFACE_KEYS: dict[str, Key] = {
    "shape": Key(choice(*SHAPES), doc="built-in shape, or a net / point grid from a file"),
    "cells": Key(scalar_or_pair(integer(1, 512), "[m_u, m_v]"), None,
                 "knot spans per direction (default: the shape's own)"),
    "degree": Key(integer(1, 7), 3, "polynomial degree of the B-splines"),
    "knots": Key(one_or_pair(choice(*KNOTS), "[u, v]"), None,
                 "knot layout per direction (default: the shape's own)"),
    "method": Key(choice(*FIT_METHODS), "interpolate",
                  "how control points are fitted to the shape"),
    "path": Key(text, None, "control net (.json/.npz) or point grid (.npy/.npz) file"),
    "frame": Key(integer(), -1, "frame of a control net file (negative from the end)"),
}

MATERIAL_KEYS: dict[str, Key] = {
    "mass": Key(_POSITIVE, 1.0, "mass density μ"),
    "damping": Key(_NONNEG, 0.0, "viscous damping γ"),
    "rayleigh": Key(_NONNEG, 0.0, "stiffness-proportional damping β"),
    "w10": Key(_NONNEG, 0.0, "tension in u"),
    "w01": Key(_NONNEG, 0.0, "tension in v"),
    "w20": Key(_NONNEG, 0.0, "bending in u"),
    "w11": Key(_NONNEG, 0.0, "twist (bending, mixed)"),
    "w02": Key(_NONNEG, 0.0, "bending in v"),
    "mass_matrix": Key(choice(*MASS_MATRICES), "consistent", "consistent or lumped mass"),
}

FREE_REGION_KEYS: dict[str, Key] = {
    "u": Key(_RANGE, None, "parameter range in u of the moving control points"),
    "v": Key(_RANGE, None, "parameter range in v of the moving control points"),
}

BOUNDARY_KEYS: dict[str, Key] = {
    **{e: Key(choice(*PRESETS), "free", f"edge {e[0]} = {'0' if e[1] == '0' else 'L'}")
       for e in EDGES},
    "free_region": Key(lambda v: v, None, "only control points with Greville abscissae "
                                          "in this box move"),
}

LOAD_KEYS: dict[str, Key] = {
    "kind": Key(choice(*LOAD_KINDS), doc="point force, uniform force per area, or pressure"),
    "at": Key(vector(2, _REAL, "[u, v]"), None, "parameters of a point force"),
    "force": Key(vector(3, _REAL, "[fx, fy, fz]"), None, "force (point) or force per area"),
    "q": Key(_REAL, None, "pressure along the initial normal x_u × x_v"),
    "profile": Key(choice(*PROFILES), "constant", "time profile s(t) scaling the load"),
    "t_on": Key(_TIME0, 0.0, "step: switch-on time"),
    "t_off": Key(number(0.0, allow_inf=True), math.inf, "step: switch-off time"),
    "points": Key(array_of(vector(2, _REAL, "[t, s]"), "[t, s] pairs", 1), None,
                  "piecewise: scale s from time t on"),
    "omega": Key(_POSITIVE, None, "harmonic: angular frequency ω in sin(ωt + φ)"),
    "phase": Key(_REAL, 0.0, "harmonic: phase φ"),
}

#: load keys allowed for each kind and each profile
LOAD_KIND_KEYS = {"point": ("at", "force"), "uniform": ("force",), "pressure": ("q",)}
PROFILE_KEYS = {"constant": (), "step": ("t_on", "t_off"), "piecewise": ("points",),
                "harmonic": ("omega", "phase")}

SOLVE_KEYS: dict[str, Key] = {
    "kind": Key(choice(*SOLVE_KINDS), doc="static equilibrium, free vibration modes, or motion"),
    "method": Key(choice(*METHODS), "analytic", "time integration (dynamic)"),
    "t_end": Key(_TIME, None, "end time (dynamic)"),
    "frames": Key(integer(2, 100000), 50, "number of equally spaced frames in [0, t_end]"),
    "times": Key(array_of(_TIME0, "times >= 0", 1), None, "explicit frame times"),
    "modes": Key(integer(0, 1000), 6, "number of vibration modes to report"),
    "rtol": Key(number(0.0, 1.0, open_low=True), 1e-8, "relative tolerance (rk45..bdf)"),
    "atol": Key(_POSITIVE, 1e-10, "absolute tolerance (rk45..bdf)"),
    "dt": Key(_POSITIVE, None, "time step (newmark, genalpha, radau3/5/7); default "
                          "t_end / (20 (frames - 1)), Radau one step per frame"),
    "function_samples": Key(integer(1, 100000), 400, "analytic: samples of a time-dependent "
                                                     "load profile"),
}

#: keys of [solve] used by each kind / method
SOLVE_KIND_KEYS = {"static": ("frames",), "modes": ("modes", "frames"),
                   "dynamic": ("method", "t_end", "frames", "times", "modes", "rtol", "atol",
                               "dt", "function_samples")}

OUTPUT_KEYS: dict[str, Key] = {
    "formats": Key(array_of(choice(*FORMATS, *FORMAT_ALIASES), "format names"), ("report",),
                   "what to write"),
    "resolution": Key(integer(2, 1024), 32, "tessellation samples per direction"),
    "probes": Key(array_of(vector(2, _REAL, "[u, v]"), "[u, v] pairs"), (),
                  "points whose displacement is reported and plotted"),
    "time": Key(_TIME0, None, "state written as a mesh (default: the last frame)"),
}

TOP_KEYS: dict[str, Key] = {
    "title": Key(text, "", "a one-line title, shown in reports"),
    "description": Key(text, "", "free text, copied to the report"),
}

TABLES: dict[str, dict[str, Key]] = {
    "surface": SURFACE_KEYS, "material": MATERIAL_KEYS, "boundary": BOUNDARY_KEYS,
    "load": LOAD_KEYS, "solve": SOLVE_KEYS, "output": OUTPUT_KEYS,
}


def documented_keys() -> list[str]:
    """Every key path a scenario may contain, as listed in ``docs/scenario.md``.

    Array tables are written without index (``load.force``); shape parameters as
    ``surface.<name>``; the free region as ``boundary.free_region.u``.
    """
    keys = list(TOP_KEYS)
    for table, schema in TABLES.items():
        keys += [f"{table}.{k}" for k in schema]
    keys += [f"boundary.free_region.{k}" for k in FREE_REGION_KEYS]
    for params in SHAPE_PARAMETERS.values():
        keys += [f"surface.{k}" for k in params if f"surface.{k}" not in keys]
    return keys


