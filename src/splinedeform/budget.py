"""Resources of a run, estimated from its scenario before any work starts.

Per-key limits of a scenario multiply freely (frames × resolution², frames × formats,
``t_end / dt`` × net size), so a file that passes every key check can still ask for tens of
GiB or hours. :func:`estimate` predicts four quantities from the scenario and its built model
(cheap: assembly only), each as a sum of terms that name the keys driving them:

``memory`` (bytes, peak)
    the frames' control nets ``F n_u n_v 3 · 8`` held for the whole run, plus the largest
    stage: surface samples of every frame ``F r² 3 · 8`` (probes, ``vtu``, viewer, animation
    each tessellate all frames at once), a dense eigenproblem ``4 n² · 8``, or one of the
    outputs' (animation images, the probe picture, CAD surfaces);
``disk`` (bytes) and ``files``
    every output format's, per frame (see :mod:`splinedeform.budget_outputs`);
``work`` (floating-point operations, about 1e9 per second on a laptop core)
    dense eigenproblem ``10 n³``, modal synthesis ``6 F n²`` (dense modal basis), time
    stepping ``(t_end / dt) · max(12 n (2p + 1)², 2·10⁴)`` (sparse solve per step, at least
    the interpreter's cost of one step), adaptive explicit integrators about
    ``e t_end ω_max`` right-hand sides (:func:`explicit_work`, :func:`highest_frequency`),
    implicit adaptive ones ``t_end ω_max / 3`` steps, and every output's sampling,
    probes, pictures, animations and CAD surfaces (:mod:`splinedeform.budget_outputs`);

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
#: operation-equivalent of the interpreter's work per time step
STEP_OVERHEAD = 2e4
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


def net_size(model: Any) -> tuple[int, int, int]:
    """``(n_u, n_v, p)``: the model's control net and its highest degree; a body's patches
    are counted as one net of all their control points (``n_u = Σ n_u n_v``, ``n_v = 1``)."""
    patches = getattr(model, "patches", None) or (model.surface,)
    if len(patches) == 1:
        n_u, n_v = patches[0].shape
    else:
        n_u, n_v = sum(s.shape[0] * s.shape[1] for s in patches), 1
    return n_u, n_v, max(max(s.basis_u.degree, s.basis_v.degree) for s in patches)


def estimate(scenario: Any, model: Any) -> Estimate:
    """Resources of running ``scenario`` with its built ``model`` (see the module docstring)."""
    from .budget_outputs import output_terms

    solve = scenario.solve
    F = len(solve.frame_times()) if solve.kind == "dynamic" else solve.frames
    frames_key = "solve.times" if solve.kind == "dynamic" and solve.times is not None \
        else "solve.frames"
    n_u, n_v, p = net_size(model)
    G, n = n_u * n_v, model.n_free
    outputs = output_terms(scenario, model, F, frames_key)

    nets = Term(F * G * 24.0, f"{F} frames x {n_u} x {n_v} control points x 24 bytes",
                (frames_key, "surface.cells"))
    stages = outputs["memory"]
    dense = solve.kind != "static" and (solve.method == "analytic" or solve.modes > 0) \
        and _strategy(model) == "dense"
    if dense:
        stages.append(Term(32.0 * n * n, f"dense eigenproblem of {n} free coordinates",
                           ("surface.cells", "boundary")))
    memory = [nets, max(stages, key=lambda t: t.amount)]

    work = outputs["work"]
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
    elif solve.kind == "dynamic" and solve.method in EXPLICIT_EVALUATIONS:
        work.append(explicit_work(solve, model))
    elif solve.kind == "dynamic" and solve.method != "analytic":
        steps = max(float(solve.t_end or 0.0) * highest_frequency(model) / 3.0, F)
        work.append(Term(steps * per_step, f"about {steps:.3g} steps of {solve.method} "
                                           f"(t_end x highest frequency / 3)",
                         ("solve.t_end", "solve.method", "surface.cells")))
    return Estimate(memory=memory, disk=outputs["disk"], files=outputs["files"], work=work)


#: right-hand sides an adaptive explicit integrator evaluates per radian of ``ω_max t``
#: at the default tolerances (measured: RK45 5-17, DOP853 3.5-7.6 on clamped plates and
#: membranes of 3² to 32² cells; stability bounds the step by a few ``1 / ω_max``)
EXPLICIT_EVALUATIONS = {"rk45": 20.0, "dop853": 10.0}
#: operation-equivalent of the interpreter's work per right-hand side of ``solve_ivp``
EVALUATION_OVERHEAD = 1e5
#: power iterations of :func:`highest_frequency` (with a sparse factorisation of ``M``)
POWER_ITERATIONS = 30
#: above this many free coordinates :func:`highest_frequency` skips the factorisation
#: (1.6 s at 9 801 free coordinates on a busy laptop core, 7 s at 19 321)
POWER_LIMIT = 10_000
#: the Gershgorin rows lie within this factor below ``ω_max`` (degrees 1 to 5)
GERSHGORIN_FACTOR = 2.5


def highest_frequency(model: Any) -> float:
    """Estimate of ``ω_max = sqrt(λ_max(M⁻¹ K))``, cheap enough before any eigenproblem.

    The larger of two lower bounds: the Gershgorin rows over the mass diagonal,
    ``sqrt(max_i Σ_j |K_ij| / M_ii)``, and the Rayleigh quotient ``sqrt(xᵀKx / xᵀMx)``
    after :data:`POWER_ITERATIONS` power iterations ``x ← M⁻¹ K x`` from a sign pattern
    (``M`` factorised once). On clamped plates and membranes of degree 1 to 5 it lies
    within 10 % below the true ``ω_max``. Beyond :data:`POWER_LIMIT` free coordinates
    the factorisation is skipped and the Gershgorin rows, which lie within a factor 2.5
    below ``ω_max`` there, are multiplied by that factor (an estimate up to 2.5 too high).
    """
    import numpy as np
    import scipy.sparse.linalg as spla

    M, _, K = model.matrices()
    if K.shape[0] == 0:
        return 0.0
    stiffness = np.asarray(abs(K).sum(axis=1)).ravel()
    mass = M.diagonal()
    ratio = np.where(mass > 0, stiffness / np.where(mass > 0, mass, 1.0), 0.0)
    bound = float(ratio.max())
    if K.shape[0] > POWER_LIMIT:
        return GERSHGORIN_FACTOR * float(np.sqrt(bound))
    try:
        mass_lu = spla.splu(M.tocsc())
    except RuntimeError:       # singular mass matrix: the solver says so itself
        return float(np.sqrt(bound))
    x = np.where(np.random.default_rng(0).random(K.shape[0]) < 0.5, -1.0, 1.0)
    for _ in range(POWER_ITERATIONS):
        y = mass_lu.solve(K @ x)
        size = np.linalg.norm(y)
        if not size > 0 or not np.isfinite(size):
            break
        x = y / size
    quotient = float(x @ (K @ x)) / float(x @ (M @ x))
    if np.isfinite(quotient):
        bound = max(bound, quotient)
    return float(np.sqrt(bound))


def explicit_work(solve: Any, model: Any) -> Term:
    """Work of an adaptive explicit integrator (``rk45``, ``dop853``) over ``[0, t_end]``.

    Its step is bounded by stability to a few ``1 / ω_max``, whatever the load, so it
    evaluates the right-hand side about ``e t_end ω_max`` times (``e`` from
    :data:`EXPLICIT_EVALUATIONS`), each a sparse solve with ``M`` and products with ``K``
    and ``C`` for up to 3 columns: ``6 (nnz K + nnz C + 4 n (2p + 1)²)`` operations
    (the factors of ``M`` taken as ``4 n (2p + 1)²`` entries) plus
    :data:`EVALUATION_OVERHEAD`.
    """
    M, C, K = model.matrices()
    n = model.n_free
    p = net_size(model)[2]
    omega = highest_frequency(model)
    evaluations = EXPLICIT_EVALUATIONS[solve.method] * float(solve.t_end or 0.0) * omega
    per_evaluation = 6.0 * (K.nnz + C.nnz + 4.0 * n * (2 * p + 1) ** 2) + EVALUATION_OVERHEAD
    return Term(evaluations * per_evaluation,
                f"about {evaluations:.3g} right-hand sides of {solve.method} "
                f"({EXPLICIT_EVALUATIONS[solve.method]:g} x t_end x highest frequency "
                f"{omega:.3g}) on {n} free coordinates",
                ("solve.t_end", "solve.method", "surface.cells"))


def net_memory(cells_u: int, cells_v: int, degree: int = 3) -> float:
    """Bytes of a plane net and its assembled model, estimated before building it:
    ``G (3 · 8 + 3 (2p + 1)² · 12)`` for ``G = (c_u + p)(c_v + p)`` control points (their
    coordinates, and mass, damping and stiffness in compressed sparse rows, 12 bytes an
    entry, ``(2p + 1)²`` entries a row)."""
    G = float(cells_u + degree) * float(cells_v + degree)
    return G * (24.0 + 3.0 * (2 * degree + 1) ** 2 * 12.0)


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
