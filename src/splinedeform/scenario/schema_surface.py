"""The ``[surface]`` table of a scenario: one pydantic model per ``surface.shape``
(see :mod:`.schema`)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Optional, Union

from pydantic import BaseModel, ConfigDict, Field, Strict, model_validator

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

# -- [surface] ---------------------------------------------------------------------------------
Inserted = Annotated[int, Strict(), Field(ge=0, le=64)]
Added = Annotated[int, Strict(), Field(ge=0, le=6)]
#: one count for both directions, ``[k_u, k_v]`` or ``{u = k_u, v = k_v}`` (a missing one is 0)
Insertions = Union[Inserted, tuple[Inserted, Inserted], dict[Literal["u", "v"], Inserted]]
Elevations = Union[Added, tuple[Added, Added], dict[Literal["u", "v"], Added]]


class _Refined(_Table):
    refine: Optional[Insertions] = Field(
        None, title="[k_u, k_v]", description=(
            "knots inserted at equal distances into every knot span of the built or read "
            "surface (`{u = k, v = k}`, `[k_u, k_v]` or one `k` for both; Boehm's algorithm, "
            "rational surfaces in homogeneous coordinates): the geometry does not move, every "
            "span becomes `k + 1`; on a body of CAD faces every face alike, in its own u and "
            "v, and where the counts differ in u and v each shared edge gets the knots of "
            "its other side inserted, so that both sides keep the same knots"),
        json_schema_extra={"doc_default": "0"})
    elevate: Optional[Elevations] = Field(
        None, title="[p_u, p_v]", description=(
            "degrees added to the built or read surface before `refine` (exact degree "
            "elevation: same geometry, same continuity at every knot); not in a periodic "
            "direction; on a body of CAD faces every face alike, and where the counts "
            "differ in u and v the lower degree of each shared edge is raised to its other "
            "side's"),
        json_schema_extra={"doc_default": "0"})


TRIM_EDGES = ("free", "pinned", "clamped")


class TrimCircle(_Table):
    centre: Pair = Field(title="[u, v]", description="centre of the circle in (u, v)")
    radius: Positive = Field(description="radius in parameter units")


class TrimSpline(_Table):
    points: list[Pair] = Field(min_length=4, title="[u, v] pairs", description=(
        "control points of a closed uniform B-spline curve in (u, v) (the curve closes "
        "itself: the last point is not repeated)"))
    degree: Annotated[int, Strict(), Field(ge=1, le=5)] = Field(
        3, description="degree of the curve (needs at least degree + 2 points)")


class TrimLoop(_Table):
    name: Optional[Text] = Field(None, description=(
        "a name for the loop in messages (default `outer`, `hole1`, `hole2`, … in order)"))
    polygon: Optional[list[Pair]] = Field(None, min_length=3, title="[u, v] pairs",
                                          description="the vertices of a closed polygon")
    circle: Optional[TrimCircle] = Field(None, description="`{centre = [u, v], radius = r}`")
    spline: Optional[TrimSpline] = Field(None, description=(
        "`{points = [[u, v], …], degree = 3}`: a closed B-spline curve"))
    edge: Literal[TRIM_EDGES] = Field(  # type: ignore[valid-type]
        "free", description=(
            "edge condition along the loop: pinned holds it (`d = 0`), clamped also holds its "
            "slope (`∂n d = 0`), both by Nitsche's method"))

    @model_validator(mode="after")
    def _one_curve(self) -> "TrimLoop":
        given = [k for k in ("polygon", "circle", "spline") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("a trim loop is exactly one of polygon, circle or spline, got "
                             + (" and ".join(given) or "none"))
        return self


class Trim(_Table):
    loops: list[TrimLoop] = Field(min_length=1, description=(
        "the trim loops, each `{name, polygon | circle | spline, edge}`: the first is the "
        "outer loop, the others holes in it (all holes with `rectangle`)"))
    rectangle: Annotated[bool, Strict()] = Field(False, description=(
        "the outer loop is the parameter rectangle itself: every loop is a hole in it, and "
        "the rectangle's edges keep their `[boundary]` conditions"))


class _Fitted(_Refined):
    cells: Optional[Union[Cells, tuple[Cells, Cells]]] = Field(
        None, title="[m_u, m_v]", description=(
            "knot spans per direction (the net has `cells + degree` control points per "
            "open/uniform direction, `cells` per periodic one)"),
        json_schema_extra={"doc_default": "the shape's own (see below)"})
    degree: Annotated[int, Strict(), Field(ge=1, le=7)] = Field(
        3, description="polynomial degree of the B-splines (bending weights need ≥ 2)")
    knots: Optional[Union[Knots, tuple[Knots, Knots]]] = Field(
        None, title="[u, v]", description=(
            "knot layout per direction, one for both or [u, v]; closed shapes are periodic "
            "around"),
        json_schema_extra={"doc_default": "the shape's own"})
    method: Literal[FIT_METHODS] = Field(  # type: ignore[valid-type]
        "interpolate", description=(
            "how control points are fitted to the shape (collocation at Greville points, L2 "
            "projection, local quasi-interpolant); a point grid allows `interpolate` and `l2`"))
    trim: Optional[Trim] = Field(
        None, title="{loops = [...]}", description=(
            "a trimmed region in (u, v): `[[surface.trim.loops]]` tables, each a `polygon`, "
            "`circle` or `spline`, with a `name` and an `edge` condition (docs/trim.md); the "
            "model then lives on the region inside the outer loop and outside the holes "
            "(physics `parametric`; the rectangle's edges free unless `rectangle`)"),
        json_schema_extra={"doc_default": "none (the whole rectangle)"})


Size = Union[Positive, tuple[Positive, Positive]]
SIZE_DOC = "side lengths [L_u, L_v] (or one for both); the domain is [0, L_u] × [0, L_v]"


class Plane(_Fitted):
    shape: Literal["plane"]
    size: Size = Field(1.0, title="[L_u, L_v]", description=(
            "side lengths; the domain is `[0, L_u] × [0, L_v]`"))


class Tile(_Fitted):
    shape: Literal["tile"]
    radius: Positive = Field(1.0, description="radius")
    angle: Annotated[float, Strict(), Field(gt=0, le=2 * math.pi, allow_inf_nan=False)] = Field(
        math.pi / 2, description="opening angle of the arc (radians)",
        json_schema_extra={"doc_default": 'π/2'})
    length: Positive = Field(2.0, description="length along the axis")


class HalfSphere(_Fitted):
    shape: Literal["half_sphere"]
    radius: Positive = Field(1.0, description="radius")


class Cylinder(_Fitted):
    shape: Literal["cylinder"]
    radius: Positive = Field(1.0, description="radius")
    height: Positive = Field(2.0, description="height along z")


class Torus(_Fitted):
    shape: Literal["torus"]
    R: Positive = Field(1.0, description="radius of the centre line")
    r: Positive = Field(0.4, description="tube radius (< R)")


class Saddle(_Fitted):
    shape: Literal["saddle"]
    size: Size = Field(1.0, title="[L_u, L_v]", description=(
            "side lengths; the domain is `[0, L_u] × [0, L_v]`"))
    height: Real = Field(0.25, description=(
            "`z = height (ξ² − η²)` with `ξ = 2u/L_u − 1`, `η = 2v/L_v − 1`"))


class FromFile(_Fitted):
    shape: Literal["file"]
    path: Text = Field(
        description=(
            "`.json` / `.npz` control net written by `splinedeform` (`output.formats` "
            "`json`/`npz`), or a point grid `(N_u, N_v, 3)` in `.npy` (or `.npz` with one array "
            "or an array `points`); for `cad` a `.3dm`, STEP or IGES file; relative to the "
            "scenario file, and inside its folder (see below)"),
        json_schema_extra={"doc_default": "required for `file` and `cad`"})
    frame: Integer = Field(-1, description=(
            "which frame of a control net file (negative counts from the end)"))


FaceNumber = Annotated[int, Strict(), Field(ge=0)]
FaceName = Annotated[str, Strict(), Field(min_length=1)]


class FromCad(_Refined):
    shape: Literal["cad"]
    path: Text = Field(
        description=(
            "CAD file holding NURBS surfaces: openNURBS `.3dm` (the `cad` extra), STEP "
            "`.stp`/`.step` or IGES `.igs`/`.iges` (the `cad-step` extra); relative to the "
            "scenario file, and inside its folder (as for `file`)"),
        json_schema_extra={"doc_default": "required for `cad`"})
    face: Annotated[int, Strict(), Field(ge=0)] = Field(0, description=(
            "which surface of the file, counting plain surfaces and Brep faces in file "
            "order from 0, read alone; a trimmed face is simulated on its trimmed region "
            "(`trimmed`)"),
        json_schema_extra={"doc_default": "every face (`faces`)"})
    trimmed: Optional[Annotated[bool, Strict()]] = Field(
        None, description=(
            "simulate a trimmed face on the region inside its trim loops (loops `outer`, "
            "`hole1`, …; an outer loop that is the parameter rectangle keeps the `[boundary]` "
            "edges; `[boundary.loops]` holds the loops): `true` refuses a face the trimmed "
            "model cannot take (periodic, repeated interior knots), `false` takes the whole "
            "underlying surface"),
        json_schema_extra={"doc_default": "the trim where the model can take it, else the "
                                          "whole surface with one warning"})
    faces: Optional[Union[Literal["all"], Annotated[list[FaceNumber], Field(min_length=1)],
                          Annotated[list[FaceName], Field(min_length=1)]]] = Field(
        None, description=(
            "several faces read as one body: `\"all\"` (every face of every surface object), "
            "face numbers (as `splinedeform faces FILE` lists them) or names of objects or "
            "layers (`.3dm`), with the file's topology (shared edges, seams); one face "
            "chosen (a file of one face) is the same as `face`; not with `face`"),
        json_schema_extra={"doc_default": '"all" unless `face` is given'})
    units: Optional[Literal[CAD_UNITS]] = Field(  # type: ignore[valid-type]
        None, description=(
            "length unit of the file's coordinates, overriding the unit the file declares "
            "(the numbers are kept, only their unit changes); the run computes in it, "
            "reports it and writes `3dm`, `step`, `iges` outputs in it"),
        json_schema_extra={"doc_default": "the file's"})


#: every ``surface.shape``; a new shape is one model here
SHAPE_MODELS = (Plane, Tile, HalfSphere, Cylinder, Torus, Saddle, FromFile, FromCad)
SHAPES = tuple(m.model_fields["shape"].annotation.__args__[0] for m in SHAPE_MODELS)
Surface = Annotated[Union[SHAPE_MODELS], Field(discriminator="shape")]  # type: ignore[valid-type]
