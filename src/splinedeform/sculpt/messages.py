"""Messages from the sculpting page to the server, validated with pydantic.

Every field is bounded and finite, of its own JSON type (strict: ``true`` is no number,
``"1"`` no weight, ``1.0`` no index) and no extra key is accepted, so a malformed or hostile
message is refused with a message naming the field before anything is computed. What the
physics allows beyond that (a boundary preset the surface cannot take, weights leaving a
deformation without energy) is refused by the scenario validator and the model.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, Strict, ValidationError, model_validator

MAX_PUSHES = 20000
"""Most force segments one save may hold (a drag changes the force once per frame)."""
MAX_BODY = 4 * 2**20
"""Largest request body in bytes (20000 pushes in JSON take about 2 MiB)."""

Real = Annotated[float, Strict()]
"""A JSON number (an integer is one too), never a boolean or a string."""
Count = Annotated[int, Strict()]
"""A JSON integer, never a boolean, a string or a number with a fraction."""
Weight = Annotated[Real, Field(ge=0.0, le=1e8)]
Edge = Literal["free", "pinned", "clamped", "pole"]
Component = Annotated[Real, Field(ge=-1e12, le=1e12)]
Time = Annotated[Real, Field(ge=0.0, le=1e9)]


class _Message(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=False)


class MaterialMessage(_Message):
    """Material weights and damping: ``[material]`` of a scenario (``mass > 0``)."""

    mass: Annotated[Real, Field(gt=0.0, le=1e8)] = 1.0
    damping: Weight = 0.0
    rayleigh: Weight = 0.0
    w10: Weight = 0.0
    w01: Weight = 0.0
    w20: Weight = 0.0
    w11: Weight = 0.0
    w02: Weight = 0.0


FaceNumber = Annotated[str, Field(pattern=r"^[0-9]{1,6}$")]
"""A face of a body by its number in the file, as a JSON key."""
SideName = Literal["u0", "u1", "v0", "v1"]
MAX_FACES = 4096
"""Most faces one message may name (the finest body the page draws has fewer)."""


class BoundaryMessage(_Message):
    """Boundary preset per edge: ``[boundary]`` of a scenario; a body's ``u0`` is the preset
    of every boundary edge, ``faces`` (``boundary.faces``: ``{"3": {"v1": "clamped"}}``,
    the file's face numbers) replaces it edge by edge."""

    u0: Edge = "free"
    u1: Edge = "free"
    v0: Edge = "free"
    v1: Edge = "free"
    faces: Annotated[dict[FaceNumber, dict[SideName, Edge]],
                     Field(max_length=MAX_FACES)] | None = None


Parameter = Annotated[Real, Field(ge=-1e6, le=1e6)]


class FreeRegionMessage(_Message):
    """``boundary.free_region``: only control points with Greville abscissae in the box move."""

    u: tuple[Parameter, Parameter] | None = None
    v: tuple[Parameter, Parameter] | None = None


MAX_NET_POINTS = 160000
"""Most control points a painted free set may list (a 400 x 400 net)."""
NetIndex = Annotated[Count, Field(ge=0, le=100000)]


NetPoints = Annotated[list[tuple[NetIndex, NetIndex]], Field(max_length=MAX_NET_POINTS)]
"""Control points listed ``[i, j]``: row ``i`` along u, column ``j`` along v, from 0."""
FacesPoints = Annotated[dict[FaceNumber, NetPoints], Field(max_length=MAX_FACES)]
"""A body's painted control points per face, keyed by the file's face number."""


def _one_free_set(message: "ResolveMessage | BakeMessage") -> "ResolveMessage | BakeMessage":
    """``message`` if it names at most one kind of free set, within :data:`MAX_NET_POINTS`."""
    total = sum(len(points) for points in (message.faces_free_points or {}).values())
    if total > MAX_NET_POINTS:
        raise ValueError(f"faces_free_points lists {total} control points, more than "
                         f"the {MAX_NET_POINTS} one message may hold")
    if message.free_points is not None and message.faces_free_points is not None:
        raise ValueError("give free_points (one surface) or faces_free_points (a "
                         "body's faces), not both")
    return message


class ResolveMessage(_Message):
    """Re-solve the modes with a new material, boundary and moving set: a box
    (``free_region``), control points listed ``[i, j]`` (``free_points``, what the page
    paints on one surface; ``faces_free_points`` ``{"3": [[i, j], …]}`` on a body's faces,
    the other faces moving), or neither (the whole net moves). A body's painted points
    together are at most :data:`MAX_NET_POINTS`."""

    material: MaterialMessage
    boundary: BoundaryMessage
    free_region: FreeRegionMessage | None = None
    free_points: NetPoints | None = None
    faces_free_points: FacesPoints | None = None

    @model_validator(mode="after")
    def _bounded(self) -> "ResolveMessage":
        return _one_free_set(self)


class CorrectionMessage(_Message):
    """The static correction column of one sample point of basis ``version``."""

    version: Annotated[Count, Field(ge=0)]
    index: Annotated[Count, Field(ge=0)]


class PushMessage(_Message):
    """A force ``force`` held at sample ``index`` for ``t_on <= t < t_off`` (None: still held)."""

    index: Annotated[Count, Field(ge=0)]
    force: tuple[Component, Component, Component]
    t_on: Time
    t_off: Time | None = None


class SaveMessage(_Message):
    """The session as a scenario: the pushes on basis ``version`` up to time ``t_end``."""

    version: Annotated[Count, Field(ge=0)]
    t_end: Annotated[Real, Field(gt=0.0, le=1e9)]
    pushes: Annotated[list[PushMessage], Field(max_length=MAX_PUSHES)]


_JSON_TYPES = ((bool, "true/false"), (str, "a string"), (int, "an integer"),
               (float, "a number"), (type(None), "null"), (dict, "an object"),
               (list, "an array"), (tuple, "an array"))


def _json_type(value: object) -> str:
    return next((name for kind, name in _JSON_TYPES if isinstance(value, kind)),
                type(value).__name__)


def describe_error(exc: ValidationError) -> str:
    """One line per problem, ``key.path: what is wrong (got <JSON type>)``; the input itself
    is not echoed, only its type."""
    lines = []
    for err in exc.errors()[:10]:
        where = ".".join(str(p) for p in err["loc"]) or "message"
        got = "" if err["type"] in ("missing", "extra_forbidden") else \
            f" (got {_json_type(err.get('input'))})"
        lines.append(f"{where}: {err['msg']}{got}")
    more = exc.error_count() - len(lines)
    if more > 0:
        lines.append(f"... and {more} more")
    return "; ".join(lines)


class BakeMessage(_Message):
    """Make the shape of modal state ``q`` (``3 k`` numbers, mode-major ``[q_1x, q_1y, q_1z,
    q_2x, …]``) on basis ``version`` the rest shape, with the free set ``free_points`` if
    given (a pin on one surface), or a body's ``faces_free_points`` (a pin on a body: its
    painted set less the pinned point, keyed by the face numbers of basis ``version``)."""

    version: Annotated[Count, Field(ge=0)]
    q: Annotated[list[Annotated[Real, Field(ge=-1e12, le=1e12)]],
                 Field(min_length=3, max_length=3 * MAX_NET_POINTS)]
    #: the free set of the baked model (a pin: the set less the pinned control point, which
    #: stays where the bake put it); None keeps the free set
    free_points: NetPoints | None = None
    #: a body's: each listed face's free set (a face not listed moves whole)
    faces_free_points: FacesPoints | None = None

    @model_validator(mode="after")
    def _bounded(self) -> "BakeMessage":
        return _one_free_set(self)


class ExportMessage(_Message):
    """Download the shape of modal state ``q`` on basis ``version`` as ``format``."""

    version: Annotated[Count, Field(ge=0)]
    q: Annotated[list[Annotated[Real, Field(ge=-1e12, le=1e12)]],
                 Field(min_length=3, max_length=3 * MAX_NET_POINTS)]
    format: Literal["3dm", "obj", "json"]


class HistoryMessage(_Message):
    """Undo or redo from basis ``version`` (the one the page shows)."""

    version: Annotated[Count, Field(ge=0)]
