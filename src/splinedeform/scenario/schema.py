"""The scenario file as typed pydantic models: the one declaration of every key.

Each key's type, constraints, default and description are written here once; the reader
checks values with them (:mod:`.checks`, :mod:`.keys`), ``docs/scenario.md``'s key
reference is written from them (:mod:`.reference`) and ``splinedeform schema`` prints their
JSON Schema. One model per table; a discriminated union where a key selects the other keys
that apply (``surface.shape``, ``load.kind``, ``solve.kind``). ``splinedeform schema`` prints
:func:`json_schema`, which editors (taplo, "Even Better TOML") use to complete and check
scenario files while they are written; ``tests/test_scenario_schema.py`` validates every
example against it. The rules tying keys together (bending needs degree >= 2, t_off > t_on,
...) live in :mod:`.validate`.

Why pydantic (v2) rather than msgspec: both validate and emit a JSON Schema, but pydantic's
schema carries each field's ``description``, bounds and discriminators the way editors and
``jsonschema`` read them, its errors report the location and the constraint broken (which
:mod:`.checks` rewords with the file's line), and it is already the common dependency of
the ASGI stack the sculpting server uses; msgspec's speed does not matter for files of a
few hundred bytes.

Extending
---------
- a shape: one model with ``shape: Literal["name"]`` and its parameters, added to
  :data:`SHAPE_MODELS`;
- a solve method: one name in ``splinedeform.model.METHODS`` (the literal below follows it);
- a load kind / solve kind: one model added to :data:`LOAD_MODELS` / :data:`SOLVE_MODELS`;
- a key: one field with its type, constraints, default and ``description``.
"""

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
from .schema_types import (PROFILES, IVP_METHODS, MASS_MATRICES, CAD_UNITS, PHYSICS,
                           SHELL_EDGES, SHELL_KEYS, PLATE_KEYS, FORMATS, FORMAT_ALIASES,
                           TIME_MAX, Real, Positive, NonNegative, Time, Integer, Text, Pair,
                           Angle, NetIndex, Cells, Knots, Preset, _Table)  # noqa: F401
from .schema_surface import (Trim, TrimCircle, TrimLoop, TrimSpline, TRIM_EDGES,  # noqa: F401
                             Inserted, Added, Insertions, Elevations, Size, SIZE_DOC,
                             SHAPE_MODELS, SHAPES, Surface, _Refined, _Fitted, Plane, Tile,
                             HalfSphere, Cylinder, Torus, Saddle, FromFile, FromCad)  # noqa: F401

# -- [material], [boundary] --------------------------------------------------------------------
class Material(_Table):
    mass: Positive = Field(1.0, description="mass per unit parameter area μ")
    damping: NonNegative = Field(0.0, description=(
            "viscous damping γ; mode i is critically damped at `γ/μ = 2 ω_i`"))
    rayleigh: NonNegative = Field(0.0, description=(
            "stiffness-proportional damping β; modal damping `c_i = γ/μ + β ω_i²`"))
    w10: NonNegative = Field(0.0, description="tension in u")
    w01: NonNegative = Field(0.0, description="tension in v")
    w20: NonNegative = Field(0.0, description="bending in u")
    w11: NonNegative = Field(0.0, description=(
            "twist (mixed bending); `w20 = w11 = w02 = D` is a Kirchhoff plate"))
    w02: NonNegative = Field(0.0, description="bending in v")
    mass_matrix: Literal[MASS_MATRICES] = Field(  # type: ignore[valid-type]
        "consistent", description="Galerkin mass `μ G0⊗G0`, or its row sums on the diagonal "
                                  "(cheaper, less accurate frequencies)")
    physics: Literal[PHYSICS] = Field(  # type: ignore[valid-type]
        "parametric", description="the paper's energy per unit parameter area, the same "
                                  "plate under tension measured on the surface (isotropic "
                                  "weights), or a linear Kirchhoff–Love shell (x, y, z "
                                  "coupled; `E`, `nu`, `thickness`, `density` instead of "
                                  "`mass` and `w..`), see [physics.md](physics.md)")
    E: Optional[Positive] = Field(None, description="shell: Young's modulus",
        json_schema_extra={"doc_default": 'required for `shell`'})
    nu: Optional[Annotated[float, Strict(), Field(ge=0, lt=0.5, allow_inf_nan=False)]] = Field(
        None, description="shell: Poisson ratio, `0 ≤ ν < 0.5`",
        json_schema_extra={"doc_default": 'required for `shell`'})
    thickness: Optional[Positive] = Field(None, description="shell: thickness t",
        json_schema_extra={"doc_default": 'required for `shell`'})
    density: Optional[Positive] = Field(None, description=(
            "shell: density ρ (mass per unit volume; the mass is `ρ t` per unit surface "
            "area, and `damping` γ gives `C = (γ/(ρt)) M + β K`)"),
        json_schema_extra={"doc_default": '1 for `shell`'})


class FreeRegion(_Table):
    u: Optional[Pair] = Field(None, title="[low, high]", description=(
            "u range of the box, low < high"),
        json_schema_extra={"doc_default": 'whole range'})
    v: Optional[Pair] = Field(None, title="[low, high]", description=(
            "v range of the box, low < high"),
        json_schema_extra={"doc_default": 'whole range'})


#: edge conditions a face of a body takes (:data:`splinedeform.body.constraints.BODY_PRESETS`,
#: and the shell's own under ``physics = "shell"``)
FacePreset = Literal["free", "pinned", "clamped", "diaphragm", "symmetry"]
#: a face of a body named in ``boundary.faces``: its number in the file
FaceKey = Annotated[str, Field(pattern=r"^[0-9]+$")]


#: a trim loop of a CAD face named in ``boundary.loops``, as ``splinedeform faces`` lists it
LoopKey = Annotated[str, Field(pattern=r"^(outer|hole[1-9][0-9]*)$")]
#: a trim edge of such a loop: its number in the loop, from 0
TrimEdgeKey = Annotated[str, Field(pattern=r"^[0-9]+$")]
#: a loop's condition: one preset, or one per trim edge named
LoopPresets = Union[FacePreset, dict[TrimEdgeKey, FacePreset]]


class FaceEdges(_Table):
    u0: Optional[FacePreset] = Field(None, description="edge `u = 0` of the face")
    u1: Optional[FacePreset] = Field(None, description="edge `u = L_u` of the face")
    v0: Optional[FacePreset] = Field(None, description="edge `v = 0` of the face")
    v1: Optional[FacePreset] = Field(None, description="edge `v = L_v` of the face")


class Boundary(_Table):
    u0: Preset = Field("free", description=(
            "edge `u = 0`: pinned holds it (`d = 0`), clamped also holds its slope (`∂n d = 0`; "
            "on a curved shell its rotation `a₃·∂n d = 0`), pole makes a collapsed edge (open "
            "knots) move as one point; shell only: diaphragm is rigid in the edge's "
            "coordinate plane and free out of it, symmetry puts the edge on a coordinate "
            "symmetry plane"))
    u1: Preset = Field("free", description="edge `u = L_u` (presets as `u0`)")
    v0: Preset = Field("free", description="edge `v = 0` (presets as `u0`)")
    v1: Preset = Field("free", description="edge `v = L_v` (presets as `u0`)")
    free_region: Optional[FreeRegion] = Field(
        None, description=(
            "inline table `{ u = [a, b], v = [c, d] }`: only control points whose Greville "
            "abscissae lie in this box move; all others are fixed at rest (the paper's reduced set"
            " of moving control points)"),
        json_schema_extra={"doc_default": 'none (all move)'})
    free_points: Optional[list[tuple[NetIndex, NetIndex]]] = Field(
        None, title="[i, j] pairs", description=(
            "the moving control points listed one by one, `[i, j]` = row `i` along u, column "
            "`j` along v, from 0 (what `splinedeform sculpt` paints); all others are fixed at "
            "rest; not with `free_region`"),
        json_schema_extra={"doc_default": 'none (all move)'})
    faces: Optional[dict[FaceKey, FaceEdges]] = Field(
        None, title="{k = {u0 = ...}}", description=(
            "body of CAD faces only: presets of single boundary edges, keyed by the face's "
            "number in the file (`[boundary.faces]` then `3 = { u0 = \"clamped\" }`): "
            "`free`, `pinned` or `clamped`, and under physics `shell` also `diaphragm` or "
            "`symmetry`; they replace the one preset `u0 = u1 = v0 = v1` "
            "on those edges; an edge another face meets (an interface) or a pole takes none"),
        json_schema_extra={"doc_default": "none"})
    faces_free_points: Optional[dict[FaceKey, list[tuple[NetIndex, NetIndex]]]] = Field(
        None, title="{k = [[i, j], ...]}", description=(
            "body of CAD faces only: the moving control points of single faces, keyed by the "
            "face's number in the file (`{ 0 = [[1, 2], [2, 2]], 2 = [[3, 1]] }`), each "
            "listed `[i, j]` as in `free_points` (row `i` along u, column `j` along v of that "
            "face's net, from 0); all other control points of a listed face are fixed at "
            "rest, a face not listed moves apart from its edges; a point that two faces "
            "share is fixed when either fixes it; on a trimmed face a fixed point whose "
            "B-spline meets the region stays at rest (inner or outer), the others hold "
            "nothing"),
        json_schema_extra={"doc_default": "none (all move)"})
    loops: Optional[dict[LoopKey, LoopPresets]] = Field(
        None, title='{outer = "clamped", ...}', description=(
            "trimmed CAD face only: edge conditions of the face's trim loops, named as "
            "`splinedeform faces FILE` lists them (`outer`, `hole1`, …): `free`, `pinned` "
            "or `clamped`, held by Nitsche's method; a loop made of several trim edges "
            "takes one per edge instead (`outer.0 = \"clamped\"`, the edges numbered from "
            "0 in the loop's order, those not named free); loops not named are free"),
        json_schema_extra={"doc_default": "none (free)"})


# -- [[load]] ----------------------------------------------------------------------------------
class _Profiled(_Table):
    profile: Literal[PROFILES] = Field(  # type: ignore[valid-type]
        "constant", description=(
            "time profile s(t) multiplying the load; `constant` is 1 for all t ≥ 0"))
    t_on: Time = Field(0.0, description="`step`: s = 1 from `t_on` …")
    t_off: Optional[Annotated[float, Strict(), Field(ge=0)]] = Field(
        None, description="`step`: … until `t_off` (> `t_on`, or `inf`), then 0",
        json_schema_extra={"doc_default": 'inf'})
    points: Optional[list[Pair]] = Field(None, min_length=1, title="[t, s] pairs",
                                         description=(
            "`piecewise`: [t, s] pairs, t ≥ 0 increasing; s is the value of the last point with "
            "`t_i ≤ t` (0 before the first)"),
        json_schema_extra={"doc_default": 'required for `piecewise`'})
    omega: Optional[Annotated[float, Strict(), Field(gt=0, le=OMEGA_MAX, allow_inf_nan=False)]] = Field(None, description="`harmonic`: `s = sin(ω t + φ)`",
        json_schema_extra={"doc_default": 'required for `harmonic`'})
    phase: Real = Field(0.0, description="`harmonic`: φ")


class _OnFace(_Profiled):
    face: Optional[Annotated[int, Strict(), Field(ge=0)]] = Field(
        None, description=(
            "body of CAD faces only: the face (its number in the file, as `splinedeform "
            "faces FILE` lists it) the load acts on; a point load's `at` are that face's "
            "parameters"),
        json_schema_extra={"doc_default": "every face (required for `point` on a body)"})


class PointLoad(_OnFace):
    kind: Literal["point"]
    at: Pair = Field(title="[u, v]", description="where a point force acts",
        json_schema_extra={"doc_default": 'required for `point`'})
    force: tuple[Real, Real, Real] = Field(title="[fx, fy, fz]", description=(
            "the force (point) or force per parameter area (uniform; per unit surface area "
            "under physics `shell`)"),
        json_schema_extra={"doc_default": 'required for `point`, `uniform`'})


class UniformLoad(_OnFace):
    kind: Literal["uniform"]
    force: tuple[Real, Real, Real] = Field(title="[fx, fy, fz]", description=(
            "the force (point) or force per parameter area (uniform; per unit surface area "
            "under physics `shell`)"),
        json_schema_extra={"doc_default": 'required for `point`, `uniform`'})


class PressureLoad(_OnFace):
    kind: Literal["pressure"]
    q: Real = Field(description=(
            "pressure; the force density is `q x0_u × x0_v`, so a positive `q` pushes along the "
            "normal `x_u × x_v` (on a body's face marked reversed in its Brep, along "
            "`-(x_u × x_v)`: the Brep's outward normal)"),
        json_schema_extra={"doc_default": 'required for `pressure`'})


#: every ``load.kind``; a new kind is one model here
LOAD_MODELS = (PointLoad, UniformLoad, PressureLoad)
LOAD_KINDS = tuple(m.model_fields["kind"].annotation.__args__[0] for m in LOAD_MODELS)
Load = Annotated[Union[LOAD_MODELS], Field(discriminator="kind")]  # type: ignore[valid-type]


# -- [solve], [output] -------------------------------------------------------------------------
Frames = Annotated[int, Strict(), Field(ge=2, le=100000)]
FRAMES_DOC = "number of equally spaced frames"


class StaticSolve(_Table):
    kind: Literal["static"]
    frames: Frames = Field(50, description=FRAMES_DOC + " (load factors in [0, 1])")


class ModesSolve(_Table):
    kind: Literal["modes"]
    modes: Annotated[int, Strict(), Field(ge=1, le=1000)] = Field(
        6, description="number of vibration modes to report")
    frames: Frames = Field(50, description=FRAMES_DOC + " (phases over one period)")


class DynamicSolve(_Table):
    kind: Literal["dynamic"]
    method: Literal[METHODS] = Field(  # type: ignore[valid-type]
        "analytic", description=(
            "dynamic: the closed-form modal solution, or a numerical reference integrator"))
    t_end: Optional[Annotated[float, Strict(), Field(gt=0, le=TIME_MAX)]] = Field(
        None, description="end time",
        json_schema_extra={"doc_default": 'required for dynamic (or from `times`)'})
    frames: Frames = Field(50, description=(
            "number of frames: equally spaced times in `[0, t_end]` (dynamic), load factors in "
            "`[0, 1]` (static: `λ d`, the problem is linear), phases over one period of the lowest"
            " mode (modes)"))
    times: Optional[list[Time]] = Field(None, min_length=1, title="times >= 0",
                                        description=(
            "dynamic: explicit increasing frame times instead of `frames`"))
    modes: Annotated[int, Strict(), Field(ge=0, le=1000)] = Field(
        6, description="number of lowest vibration modes reported (`modes.png`, report); 0 "
                       "skips them in a dynamic solve")
    rtol: Annotated[float, Strict(), Field(gt=0, le=1)] = Field(
        1e-8, description="`rk45`, `dop853`, `radau`, `bdf`: relative tolerance")
    atol: Positive = Field(
        1e-10, description="`rk45`, `dop853`, `radau`, `bdf`: absolute tolerance")
    dt: Optional[Positive] = Field(
        None, description=", ".join(f"`{m}`" for m in STEP_METHODS) + ": largest time step",
        json_schema_extra={
            "doc_default": "`t_end / (20 (frames - 1))`; Radau: one step per frame"})
    function_samples: Annotated[int, Strict(), Field(ge=1, le=100000)] = Field(
        400, description=(
            "`analytic`: samples of a time-dependent load profile (applied piecewise constant)"))


#: every ``solve.kind``
SOLVE_MODELS = (StaticSolve, ModesSolve, DynamicSolve)
SOLVE_KINDS = tuple(m.model_fields["kind"].annotation.__args__[0] for m in SOLVE_MODELS)
Solve = Annotated[Union[SOLVE_MODELS], Field(discriminator="kind")]  # type: ignore[valid-type]


class Output(_Table):
    formats: list[Literal[FORMATS + tuple(FORMAT_ALIASES)]] = Field(  # type: ignore[misc]
        ["report"], title="format names", description=(
            "files to write in the output folder (names below)"))
    resolution: Annotated[int, Strict(), Field(ge=2, le=1024)] = Field(
        32, description=(
            "tessellation samples per direction for meshes, pictures, animation, viewer"))
    probes: list[Union[Pair, tuple[Real, Real, Real]]] = Field(
        [], title="[u, v] pairs (a body: or [x, y, z] points)", description=(
            "points whose displacement is reported (`report`) and plotted (`probes.png`); on "
            "a body of CAD faces `[u, v]` of the face `probe_faces` names, or a point "
            "`[x, y, z]` in space, read at the nearest point of its face (of `probe_faces`, "
            "else of the face it is nearest to)"),
        json_schema_extra={"doc_default": "the domain centre (a body: each face's centre)"})
    probe_faces: Optional[list[Annotated[int, Strict(), Field(ge=0)]]] = Field(
        None, title="face numbers", description=(
            "body of CAD faces only: the face of each probe, one per entry of `probes` (the "
            "file's face numbers, as `splinedeform faces FILE` lists them)"),
        json_schema_extra={"doc_default": "a point's nearest face (required for `[u, v]`)"})
    time: Optional[Time] = Field(None, description="dynamic: the state written as OBJ / STL / PLY",
        json_schema_extra={"doc_default": 'the last frame'})
    warp: Union[Literal["auto"], Annotated[float, Strict(), Field(gt=0, le=1e6,
                                                              allow_inf_nan=False)]] = Field(
        "auto", description=(
            "pictures and animation draw `x_rest + warp · d` (colours keep the true `|d|`); "
            '"auto": below `max |d| = 0.05 · size`, `0.2 · size / max |d|` rounded to the '
            "nearest 1, 2 or 5 × 10^k, else 1 (size: the largest side of the control net's "
            "box; 1 for a modes solve), stated in the caption"))
    camera: tuple[Angle, Angle] = Field(
        (28.0, -60.0), title="[elevation, azimuth]", description=(
            "view of the pictures and the animation, in degrees"))
    fps: Annotated[float, Strict(), Field(gt=0, le=50, allow_inf_nan=False)] = Field(
        15.0, description="frames per second of the animation (a GIF keeps hundredths of a "
                          "second per frame)")
    animate_modes: Optional[list[Annotated[int, Strict(), Field(ge=1, le=1000)]]] = Field(
        None, title="mode numbers", description=(
            "modes: the modes animated, mode 1 as `<name>.gif`, mode k as "
            "`<name>_mode<k>.gif` and the series `<name>_mode<k>.pvd`"),
        json_schema_extra={"doc_default": "[1]"})


class ScenarioFile(_Table):
    """A scenario file: one simulation (see ``docs/scenario.md``)."""

    model_config = ConfigDict(extra="forbid", title="splinedeform scenario")

    title: Text = Field("", description="one-line title, shown in the summary and the report")
    description: Text = Field("", description="free text, copied to the report")
    surface: Surface
    material: Material = Field(default_factory=Material)
    boundary: Boundary = Field(default_factory=Boundary)
    load: list[Load] = Field([], description="[[load]] tables, summed")
    solve: Solve
    output: Output = Field(default_factory=Output)


def json_schema() -> dict[str, Any]:
    """JSON Schema (draft 2020-12) of scenario files, generated from :class:`ScenarioFile`."""
    schema = ScenarioFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    return schema
