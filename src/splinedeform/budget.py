"""Resources of a run, estimated from its scenario before any work starts.

Per-key limits of a scenario multiply freely (frames × resolution², frames × formats,
``t_end / dt`` × net size), so a file that passes every key check can still ask for tens of
GiB or hours. :func:`estimate` predicts four quantities from the scenario and its built model
(cheap: assembly only), each as a sum of terms that name the keys driving them:

``memory`` (bytes, peak)
    the frames' control nets ``F n_u n_v 3 · 8`` held for the whole run, plus the largest
    stage: surface samples of every frame ``F r² 3 · 8`` (probes, ``vtu``, viewer, animation
    each tessellate all frames at once), animation images ``F · 640 · 480 · 3``, a dense
    eigenproblem ``4 n² · 8``;
``disk`` (bytes)
    ``vtu`` ``F r² · 104`` (points, displacement, magnitude, two triangles per quad), nets
    ``json`` ``F n_u n_v 3 · 25`` / ``npz`` ``· 8``, viewer ``(F r² + F n_u n_v) 3 · 4 · 4/3``,
    GIF 64 KiB and MP4 16 KiB per frame, meshes ``r² · 100`` each;
``files``
    ``F + 1`` for ``vtu``, one per other format (three pictures, two reports);
``work`` (floating-point operations, about 1e9 per second on a laptop core)
    dense eigenproblem ``10 n³``, modal synthesis ``6 F n²`` (dense modal basis), time
    stepping ``(t_end / dt) · max(12 n (2p + 1)², 2·10⁴)`` (sparse solve per step, at least
    the interpreter's cost of one step; adaptive integrators ``t_end ω_max / 3`` steps, see
    :func:`highest_frequency`), sampling ``2 F r² (p + 1)² 3`` per sampled output
    and ``5·10⁷`` per rendered animation frame;

with ``F`` frames, ``r`` = ``output.resolution``, a net of ``n_u × n_v`` control points,
``n`` free coordinates and degree ``p``. The estimates are upper-bound-minded orders of
magnitude, not measurements: their purpose is to refuse a run that cannot finish on the
machine, with the keys to change. :class:`Budget` holds the limits (defaults fit a laptop);
``splinedeform run --budget memory=16GiB,files=1e5`` raises them.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, fields
from typing import Any

from .errors import InputError

GiB = 2**30
#: bytes of one animation frame image (RGB)
IMAGE_BYTES = 640 * 480 * 3
#: operation-equivalent of the interpreter's work per time step and per rendered image
STEP_OVERHEAD = 2e4
RENDER_WORK = 5e7
#: rough speed used to put a work estimate in seconds in messages
OPS_PER_SECOND = 1e9


@dataclass(frozen=True)
class Budget:
    """Limits of one run: ``memory`` and ``disk`` in bytes, ``files``, ``work`` in operations.

    Defaults fit a laptop: 4 GiB of memory, 4 GiB of disk, 5 000 files and 1e12 operations
    (about a quarter of an hour). ``math.inf`` lifts a limit.
    """

    memory: float = 4 * GiB
    disk: float = 4 * GiB
    files: float = 5000
    work: float = 1e12

    @classmethod
    def parse(cls, text: str) -> Budget:
        """``"memory=16GiB,disk=50GB,files=1e5,work=1e13"`` (any subset; ``inf`` lifts one).

        Sizes take the suffixes ``K``/``M``/``G``/``T`` (optionally ``B`` or ``iB``),
        all binary (``1G = 2**30``).
        """
        values: dict[str, float] = {}
        names = [f.name for f in fields(cls)]
        for item in filter(None, (part.strip() for part in text.split(","))):
            key, sep, value = item.partition("=")
            key = key.strip().lower()
            if not sep or key not in names:
                raise InputError(f"budget item {item!r}: expected NAME=VALUE with NAME one of "
                                 f"{names}, e.g. memory=16GiB,files=100000")
            values[key] = _amount(value.strip(), f"budget {key}")
        return cls(**values)


def _amount(text: str, what: str) -> float:
    """A positive number with an optional binary size suffix (``16GiB``, ``1e5``, ``inf``)."""
    match = re.fullmatch(r"([0-9.eE+\-]+|inf|infinity|unlimited)\s*([kKmMgGtT]?)(i?[bB])?", text)
    try:
        assert match is not None
        number = math.inf if match.group(1).startswith(("inf", "unl")) else float(match.group(1))
    except (AssertionError, ValueError):
        raise InputError(f"{what}: expected a positive number such as 16GiB, 1e5 or inf, "
                         f"got {text!r}") from None
    if not number > 0:
        raise InputError(f"{what} must be > 0, got {text!r}")
    return number * 1024 ** " KMGT".index(match.group(2).upper() or " ")


@dataclass(frozen=True)
class Term:
    """One contribution to a resource: amount, how it is made up, the keys driving it."""

    amount: float
    formula: str
    keys: tuple[str, ...]


@dataclass
class Estimate:
    """Predicted ``memory``, ``disk``, ``files`` and ``work``, each a list of terms."""

    memory: list[Term]
    disk: list[Term]
    files: list[Term]
    work: list[Term]

    def total(self, resource: str) -> float:
        return float(sum(t.amount for t in getattr(self, resource)))

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) rows for ``splinedeform validate``."""
        return [(f"estimated {name}", show(name, self.total(name))) for name in
                ("memory", "disk", "files", "work")]


def show(resource: str, amount: float) -> str:
    """``amount`` in words: sizes in GiB/MiB, work in operations and rough seconds."""
    if resource in ("memory", "disk"):
        return f"{amount / GiB:.3g} GiB" if amount >= GiB / 10 else f"{amount / 2**20:.3g} MiB"
    if resource == "work":
        seconds = amount / OPS_PER_SECOND
        when = f"{seconds / 3600:.3g} h" if seconds > 3600 else f"{seconds:.3g} s"
        return f"{amount:.3g} operations (about {when})"
    return f"{amount:.0f}"


def estimate(scenario: Any, model: Any) -> Estimate:
    """Resources of running ``scenario`` with its built ``model`` (see the module docstring)."""
    solve, output = scenario.solve, scenario.output
    formats = set(output.formats)
    F = len(solve.frame_times()) if solve.kind == "dynamic" else solve.frames
    frames_key = "solve.times" if solve.kind == "dynamic" and solve.times is not None \
        else "solve.frames"
    r2 = output.resolution ** 2
    n_u, n_v = model.surface.shape
    G, n = n_u * n_v, model.n_free
    p = max(model.surface.basis_u.degree, model.surface.basis_v.degree)
    res, fmt = "output.resolution", "output.formats"

    nets = Term(F * G * 24.0, f"{F} frames x {n_u} x {n_v} control points x 24 bytes",
                (frames_key, "surface.cells"))
    sampled = [f for f in ("vtu", "viewer", "gif", "mp4") if f in formats]
    stages = [Term(F * r2 * 24.0 * 2, f"{F} frames x {output.resolution}² surface samples x "
                                      "48 bytes", (frames_key, res))]
    animated = [f for f in ("gif", "mp4") if f in formats]
    if animated:
        stages.append(Term(F * IMAGE_BYTES, f"{F} animation images of 640 x 480",
                           (frames_key, fmt)))
    dense = solve.kind != "static" and (solve.method == "analytic" or solve.modes > 0) \
        and _strategy(model) == "dense"
    if dense:
        stages.append(Term(32.0 * n * n, f"dense eigenproblem of {n} free coordinates",
                           ("surface.cells", "boundary")))
    memory = [nets, max(stages, key=lambda t: t.amount)]

    disk, files = [], []
    if "vtu" in formats:
        disk.append(Term(F * r2 * 104.0, f"{F} .vtu files of {output.resolution}² points",
                         (frames_key, res, fmt)))
        files.append(Term(F + 1.0, f"{F} .vtu files and a .pvd", (frames_key, fmt)))
    for ext, size in (("json", 25.0), ("npz", 8.0)):
        if ext in formats:
            disk.append(Term(F * G * 3 * size, f"control nets .{ext}", (frames_key, fmt)))
    if "viewer" in formats:
        disk.append(Term((F * r2 + F * G) * 16.0, "viewer.html", (frames_key, res, fmt)))
    for ext, size in (("gif", 65536.0), ("mp4", 16384.0)):
        if ext in formats:
            disk.append(Term(F * size, f"{F} {ext} frames", (frames_key, fmt)))
    for ext in ("obj", "stl", "ply"):
        if ext in formats:
            disk.append(Term(r2 * 100.0, f".{ext} mesh", (res, fmt)))
    others = sum(1 for f in formats if f not in ("vtu", "images", "report")) \
        + 3 * ("images" in formats) + 2 * ("report" in formats)
    if others:
        files.append(Term(float(others), "one file per other format", (fmt,)))

    work = [Term(2.0 * F * r2 * (p + 1) ** 2 * 3 * (1 + len(sampled)),
                 f"{F} frames x {output.resolution}² samples, {1 + len(sampled)} time(s)",
                 (frames_key, res))]
    if animated:
        work.append(Term(F * RENDER_WORK * len(animated), f"rendering {F} animation frames",
                         (frames_key, fmt)))
    if dense:
        work.append(Term(10.0 * n**3, f"dense eigenproblem of {n} free coordinates",
                         ("surface.cells", "boundary")))
        work.append(Term(6.0 * F * n * n, f"modal synthesis of {F} frames",
                         (frames_key, "surface.cells")))
    per_step = max(12.0 * n * (2 * p + 1) ** 2, STEP_OVERHEAD)
    if solve.kind == "dynamic" and solve.method in _step_methods():
        steps = _steps(solve, F)
        keys = ("solve.dt", "solve.t_end") if solve.dt is not None else (frames_key,)
        work.append(Term(steps * per_step, f"{steps:.3g} time steps of {solve.method} "
                                           f"(t_end / dt) on {n} free coordinates",
                         keys + ("surface.cells",)))
    elif solve.kind == "dynamic" and solve.method != "analytic":
        steps = max(float(solve.t_end or 0.0) * highest_frequency(model) / 3.0, F)
        work.append(Term(steps * per_step, f"about {steps:.3g} steps of {solve.method} "
                                           f"(t_end x highest frequency / 3)",
                         ("solve.t_end", "solve.method", "surface.cells")))
    return Estimate(memory=memory, disk=disk, files=files, work=work)


def highest_frequency(model: Any) -> float:
    """Estimate of ``ω_max``: ``sqrt(max_i Σ_j |K_ij| / M_ii)`` (Gershgorin rows over the mass
    diagonal); on clamped plates and membranes of degree 1 to 5 it lies within a factor 2.5
    below the true ``ω_max``, cheap enough to compute before any eigenproblem.

    An explicit integrator's step is bounded by about ``3 / ω_max`` for stability, so an
    adaptive one takes about ``t_end ω_max / 3`` steps; implicit ones usually fewer, which
    makes this an upper-bound-minded estimate for them.
    """
    import numpy as np

    M, _, K = model.matrices()
    if K.shape[0] == 0:
        return 0.0
    stiffness = np.asarray(abs(K).sum(axis=1)).ravel()
    mass = M.diagonal()
    ratio = np.where(mass > 0, stiffness / np.where(mass > 0, mass, 1.0), 0.0)
    return float(np.sqrt(ratio.max()))


def _strategy(model: Any) -> str:
    from .spectrum import choose

    try:
        return str(choose(model, "auto", truncated=False))
    except InputError:       # too large for dense: the solver says so itself
        return "none"


def _step_methods() -> tuple[str, ...]:
    from .model import STEP_METHODS
    return STEP_METHODS


def _steps(solve: Any, frames: int) -> float:
    """``t_end / dt``; the default ``dt = t_end / (20 (F - 1))`` (Radau: one per frame)."""
    if solve.dt is not None:
        return float(solve.t_end) / float(solve.dt)
    return 20.0 * max(frames - 1, 1)


def check(scenario: Any, model: Any, budget: Budget | None = None) -> Estimate:
    """The estimate of a run, or a located ScenarioError when it exceeds ``budget``.

    Every resource exceeded is listed with its largest term and the keys driving it; the
    error is put at the first key of the first one.
    """
    budget = budget or Budget()
    found = estimate(scenario, model)
    over, where = [], None
    for resource in ("memory", "disk", "files", "work"):
        total, limit = found.total(resource), getattr(budget, resource)
        if total <= limit:
            continue
        main = max(getattr(found, resource), key=lambda t: t.amount)
        where = where or main.keys[0]
        over.append(f"{resource}: about {show(resource, total)} ({main.formula}) against a "
                    f"budget of {show(resource, limit)}, driven by "
                    f"{', '.join(dict.fromkeys(main.keys))}")
    if over:
        raise scenario.error(where, "this run exceeds its budget; " + "; ".join(over) + ". "
                             "Change those keys, or raise the budget (splinedeform run --budget "
                             "memory=16GiB,disk=50GiB,files=1e5,work=1e13; in Python "
                             "run(..., budget=Budget(...)))")
    return found
