"""The validated scenario: one frozen dataclass per table."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..boundary import EDGES
from ..errors import ScenarioError
from .keys import MATERIAL_KEYS
from .schema import SHELL_KEYS
from .locate import _Problems


@dataclass(frozen=True)
class SurfaceSpec:
    """``[surface]``: a built-in shape with its parameters, or a file."""

    shape: str
    cells: tuple[int, int] | None = None
    degree: int = 3
    knots: str | tuple[str, str] | None = None
    method: str = "interpolate"
    path: Path | None = None
    frame: int = -1
    parameters: dict[str, Any] = field(default_factory=dict)
    #: knots inserted per span and degrees added, ``(u, v)`` (``surface.refine``, ``.elevate``)
    refine: tuple[int, int] = (0, 0)
    elevate: tuple[int, int] = (0, 0)
    #: ``surface.trim`` as read (:class:`~splinedeform.scenario.schema.Trim`), or None
    trim: Any = None

    def __post_init__(self) -> None:
        for name in ("refine", "elevate"):
            object.__setattr__(self, name, per_direction(getattr(self, name)))


def per_direction(value: Any) -> tuple[int, int]:
    """``(u, v)`` counts from one count, a pair or ``{u = …, v = …}`` (None and missing: 0)."""
    if value is None:
        return (0, 0)
    if isinstance(value, dict):
        return (int(value.get("u", 0)), int(value.get("v", 0)))
    if isinstance(value, (tuple, list)):
        return (int(value[0]), int(value[1]))
    return (int(value), int(value))


@dataclass(frozen=True)
class MaterialSpec:
    """``[material]``: the :class:`~splinedeform.material.Material` arguments and the mass,
    or (``physics = "shell"``) those of :class:`~splinedeform.ShellMaterial`.

    The mass density ``mass`` scales the mass matrix.
    """

    mass: float = 1.0
    damping: float = 0.0
    rayleigh: float = 0.0
    w10: float = 0.0
    w01: float = 0.0
    w20: float = 0.0
    w11: float = 0.0
    w02: float = 0.0
    mass_matrix: str = "consistent"
    physics: str = "parametric"
    E: float | None = None
    nu: float | None = None
    thickness: float | None = None
    density: float | None = None

    def weights(self) -> dict[str, float]:
        """Arguments of :class:`~splinedeform.material.Material`."""
        return {k: getattr(self, k) for k in MATERIAL_KEYS
                if k not in ("mass_matrix", "physics", *SHELL_KEYS)}

    def shell(self) -> dict[str, float]:
        """Arguments of :class:`~splinedeform.ShellMaterial` (``physics = "shell"``)."""
        return {k: getattr(self, k) for k in (*SHELL_KEYS, "damping", "rayleigh")}


@dataclass(frozen=True)
class BoundarySpec:
    """``[boundary]``: edge presets and an optional box of moving control points."""

    u0: str = "free"
    u1: str = "free"
    v0: str = "free"
    v1: str = "free"
    free_u: tuple[float, float] | None = None
    free_v: tuple[float, float] | None = None
    free_points: tuple[tuple[int, int], ...] | None = None

    def edges(self) -> dict[str, str]:
        return {e: getattr(self, e) for e in EDGES}

    @property
    def has_free_region(self) -> bool:
        return self.free_u is not None or self.free_v is not None or self.free_points is not None


@dataclass(frozen=True)
class LoadSpec:
    """One ``[[load]]`` table."""

    kind: str
    at: tuple[float, float] | None = None
    force: tuple[float, float, float] | None = None
    q: float | None = None
    profile: str = "constant"
    t_on: float = 0.0
    t_off: float = math.inf
    points: tuple[tuple[float, float], ...] | None = None
    omega: float | None = None
    phase: float = 0.0
    face: int | None = None


@dataclass(frozen=True)
class SolveSpec:
    """``[solve]``: what to compute and at which times."""

    kind: str
    method: str = "analytic"
    t_end: float | None = None
    frames: int = 50
    times: tuple[float, ...] | None = None
    modes: int = 6
    rtol: float = 1e-8
    atol: float = 1e-10
    dt: float | None = None
    function_samples: int = 400

    def frame_times(self) -> tuple[float, ...]:
        """Frame times: ``times`` if given, else ``frames`` equally spaced in ``[0, t_end]``."""
        if self.times is not None:
            return self.times
        t_end = self.t_end or 0.0
        return tuple(t_end * (i / (self.frames - 1)) for i in range(self.frames))


@dataclass(frozen=True)
class OutputSpec:
    """``[output]``: which files to write."""

    formats: tuple[str, ...] = ("report",)
    resolution: int = 32
    probes: tuple[tuple[float, ...], ...] = ()
    probe_faces: tuple[int, ...] | None = None
    time: float | None = None
    warp: str | float = "auto"
    camera: tuple[float, float] = (28.0, -60.0)
    fps: float = 15.0
    animate_modes: tuple[int, ...] | None = None     # None: mode 1


@dataclass(frozen=True)
class Scenario:
    """A validated scenario; build it with :func:`build`, run it with :func:`run`."""

    surface: SurfaceSpec
    material: MaterialSpec
    boundary: BoundarySpec
    loads: tuple[LoadSpec, ...]
    solve: SolveSpec
    output: OutputSpec
    title: str = ""
    description: str = ""
    source: str = "<scenario>"
    directory: Path = field(default_factory=Path.cwd)
    raw: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    lines: dict[str, int] = field(default_factory=dict, repr=False, compare=False)
    origins: dict[str, str] = field(default_factory=dict, repr=False, compare=False)
    allow_outside_paths: bool = field(default=False, repr=False, compare=False)

    @property
    def name(self) -> str:
        """File stem (or ``scenario``), used to name outputs."""
        stem = Path(self.source).stem
        return stem if stem and not stem.startswith("<") else "scenario"

    def error(self, path: str, message: str) -> ScenarioError:
        """A :class:`ScenarioError` located at ``path`` (``file:line: path: message``)."""
        problems = _Problems(self.source, self.lines, self.origins)
        problems.add(path, message)
        return ScenarioError(problems.message())


