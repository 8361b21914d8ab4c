"""Loads and their time profiles → generalised forces ``F_kl(t) = ∫∫ f(u,v,t) b_k(u) b_l(v) du dv``.

Loads are given per unit *parameter* area, like the energy (DESIGN.md §1.4–1.5):

* :class:`Point` — ``F_kl = P b_k(u_0) b_l(v_0)``;
* :class:`Uniform` — ``f = const`` (gravity-like), ``F_kl = f ∫b_k ∫b_l``;
* :class:`Pressure` — ``f = q x0_u × x0_v`` (pressure ``q`` along the initial normal,
  times the area element, so the total force is ``q`` times the true surface area);
* :class:`Function` — a user field ``f(u, v, t) -> (..., 3)``.

Each load carries a time profile ``s(t)`` (:class:`Constant` by default, :class:`Step`,
:class:`Piecewise`, :class:`Harmonic`) and loads add with ``+``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import InputError
from .knots import RationalBasis
from .quadrature import gauss_points, integrals
from .rational import weight_field
from .surface import Surface
from .trim.surface_trim import region_contains


def _finite(value: float, what: str) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number, got {value!r}") from None
    if not math.isfinite(value):
        raise InputError(f"{what} must be finite, got {value!r}")
    return value


def _vector3(force: ArrayLike, what: str) -> NDArray[np.float64]:
    try:
        vec = np.asarray(force, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be three numbers (fx, fy, fz), got {force!r}") from None
    if vec.shape != (3,):
        raise InputError(f"{what} must be three numbers (fx, fy, fz), got shape {vec.shape}")
    if not np.all(np.isfinite(vec)):
        raise InputError(f"{what} must be finite, got {vec.tolist()}")
    return vec


# --------------------------------------------------------------------------- profiles
class Profile:
    """A time profile ``s(t)`` multiplying a load's spatial part."""

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        raise NotImplementedError

    def jumps(self) -> list[tuple[float, float]] | None:
        """``[(t_j, Δs_j)]`` when ``s`` is piecewise constant (``s = Σ Δs_j H(t - t_j)``), else None."""
        return None

    def breakpoints(self) -> list[float]:
        """Times where ``s`` is not smooth (numerical solvers restart there)."""
        return [t for t, _ in (self.jumps() or [])]


@dataclass(frozen=True)
class Constant(Profile):
    """``s(t) = 1`` for ``t >= 0``."""

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        return np.where(np.asarray(t, dtype=float) >= 0, 1.0, 0.0)

    def jumps(self) -> list[tuple[float, float]]:
        return [(0.0, 1.0)]


@dataclass(frozen=True)
class Step(Profile):
    """``s(t) = 1`` for ``t_on <= t < t_off``, else 0."""

    t_on: float = 0.0
    t_off: float = math.inf

    def __post_init__(self) -> None:
        on = _finite(self.t_on, "Step.t_on")
        off = float(self.t_off)
        if math.isnan(off) or off <= on or on < 0:
            raise InputError(f"Step needs 0 <= t_on < t_off, got t_on={self.t_on}, "
                             f"t_off={self.t_off}")
        object.__setattr__(self, "t_on", on)
        object.__setattr__(self, "t_off", off)

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=float)
        return np.where((t >= self.t_on) & (t < self.t_off), 1.0, 0.0)

    def jumps(self) -> list[tuple[float, float]]:
        out = [(self.t_on, 1.0)]
        return out + ([(self.t_off, -1.0)] if math.isfinite(self.t_off) else [])


@dataclass(frozen=True)
class Piecewise(Profile):
    """Piecewise constant: ``s = s_i`` on ``[t_i, t_{i+1})``, 0 before ``t_0``, ``s_last`` after."""

    points: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        try:
            pts = tuple((float(t), float(s)) for t, s in self.points)
        except (TypeError, ValueError):
            raise InputError("Piecewise needs a list of (time, scale) pairs") from None
        if not pts:
            raise InputError("Piecewise needs at least one (time, scale) pair")
        times = np.array([p[0] for p in pts])
        if not np.all(np.isfinite(np.array(pts))) or times[0] < 0 or np.any(np.diff(times) <= 0):
            raise InputError(f"Piecewise times must be finite, >= 0 and increasing, got "
                             f"{times.tolist()}")
        object.__setattr__(self, "points", pts)

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=float)
        times = np.array([p[0] for p in self.points])
        scales = np.array([0.0] + [p[1] for p in self.points])
        return scales[np.searchsorted(times, t, side="right")]

    def jumps(self) -> list[tuple[float, float]]:
        scales = [0.0] + [s for _, s in self.points]
        return [(t, scales[i + 1] - scales[i]) for i, (t, _) in enumerate(self.points)]


#: largest angular frequency of a harmonic profile (a period of 6e-12 time units): beyond it
#: ``ω²`` and the phase ``ω t`` leave the range where the modal response keeps its digits
OMEGA_MAX = 1e12


@dataclass(frozen=True)
class Harmonic(Profile):
    """``s(t) = sin(ω t + φ)`` for ``t >= 0`` (0 before), ``0 < ω <= OMEGA_MAX``."""

    omega: float
    phase: float = 0.0

    def __post_init__(self) -> None:
        omega = _finite(self.omega, "Harmonic.omega")
        if omega <= 0:
            raise InputError(f"Harmonic.omega must be > 0, got {omega}")
        if omega > OMEGA_MAX:
            raise InputError(f"Harmonic.omega must be <= {OMEGA_MAX:g} (a period of "
                             f"{2 * np.pi / OMEGA_MAX:.1e}), got {omega:g}; rescale the time unit")
        object.__setattr__(self, "omega", omega)
        object.__setattr__(self, "phase", _finite(self.phase, "Harmonic.phase"))

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=float)
        return np.where(t >= 0, np.sin(self.omega * t + self.phase), 0.0)

    def breakpoints(self) -> list[float]:
        return [0.0]


def _profile(profile: Profile | None) -> Profile:
    if profile is None:
        return Constant()
    if not isinstance(profile, Profile):
        raise InputError(f"profile must be Constant, Step, Piecewise or Harmonic, got {profile!r}")
    return profile


# --------------------------------------------------------------------------- loads
class Load:
    """Base class: a spatial force field times a profile; loads add with ``+``."""

    profile: Profile
    time_dependent_field: bool = False

    def terms(self) -> list[Load]:
        return [self]

    def __add__(self, other: Load) -> LoadSum:
        if not isinstance(other, Load):
            return NotImplemented
        return LoadSum(tuple(self.terms()) + tuple(other.terms()))

    def field_vector(self, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
        """Spatial part ``∫∫ f b_k b_l`` (without the profile), shape ``(n_u n_v, 3)``."""
        raise NotImplementedError

    def vector(self, surface: Surface, t: float) -> NDArray[np.float64]:
        """Full generalised force ``s(t) F_kl(t)`` of all terms, shape ``(n_u n_v, 3)``."""
        return sum((term.profile(t) * term.field_vector(surface, t) for term in self.terms()),
                   np.zeros((surface.shape[0] * surface.shape[1], 3)))

    def breakpoints(self) -> list[float]:
        return sorted({b for term in self.terms() for b in term.profile.breakpoints()})

    def time_dependent(self) -> bool:
        """True when some term's profile is not ``s(t) = 1`` for every ``t >= 0``."""
        return any(term.profile.jumps() != [(0.0, 1.0)] for term in self.terms())


@dataclass(frozen=True)
class LoadSum(Load):
    """A sum of loads."""

    parts: tuple[Load, ...]

    def terms(self) -> list[Load]:
        return [t for part in self.parts for t in part.terms()]


@dataclass(frozen=True)
class Point(Load):
    """Point force ``P`` at parameters ``(u, v)``: ``F_kl = P b_k(u) b_l(v)``."""

    u: float
    v: float
    force: ArrayLike
    profile: Profile = field(default_factory=Constant)

    def __post_init__(self) -> None:
        object.__setattr__(self, "u", _finite(self.u, "Point.u"))
        object.__setattr__(self, "v", _finite(self.v, "Point.v"))
        object.__setattr__(self, "force", _vector3(self.force, "Point.force"))
        object.__setattr__(self, "profile", _profile(self.profile))

    def field_vector(self, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
        for name, value, basis in (("u", self.u, surface.basis_u), ("v", self.v, surface.basis_v)):
            if not basis.periodic and not 0.0 <= value <= basis.length:
                raise InputError(f"point load at {name}={value:g} is outside the parameter "
                                 f"domain [0, {basis.length:g}]")
        if surface.trim is not None and not region_contains(surface, [self.u, self.v]):
            raise InputError(f"point load at (u, v) = ({self.u:g}, {self.v:g}) is outside the "
                             "trimmed region of the surface")
        E = surface.evaluation_matrix(np.array([self.u]), np.array([self.v]))
        return np.asarray(E.T.toarray()) * self.force[None, :]


@dataclass(frozen=True)
class Uniform(Load):
    """Uniform force per unit parameter area: ``F_kl = f ∫ b_k du ∫ b_l dv``."""

    force: ArrayLike
    profile: Profile = field(default_factory=Constant)

    def __post_init__(self) -> None:
        object.__setattr__(self, "force", _vector3(self.force, "Uniform.force"))
        object.__setattr__(self, "profile", _profile(self.profile))

    def field_vector(self, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
        if surface.trim is not None:
            return project(surface, lambda U, V: np.broadcast_to(self.force, U.shape + (3,)))
        if surface.net_weights is not None:         # ∫∫ R_kl: no tensor product (project)
            return project(surface, lambda U, V: np.broadcast_to(self.force, U.shape + (3,)),
                           RATIONAL_POINTS)
        weights = np.outer(integrals(surface.basis_u), integrals(surface.basis_v)).ravel()
        return weights[:, None] * self.force[None, :]


#: extra Gauss points per cell of a load on general weights (as the rational plate's ``n + 10``)
RATIONAL_POINTS = 9


def project(surface: Surface, values: Callable[[NDArray, NDArray], NDArray],
            extra_points: int = 0) -> NDArray[np.float64]:
    """``∫∫ f(u,v) b_k(u) b_l(v) du dv`` by tensor Gauss quadrature, shape ``(n_u n_v, 3)``.

    ``values(U, V)`` gets 2-D parameter grids ``(Q_u, Q_v)`` and returns ``(Q_u, Q_v, 3)``.
    With ``n + 1 + extra_points`` points per cell and direction; computed as
    ``B_uᵀ W_u f W_v B_v`` (two sparse products per coordinate). A trimmed surface
    integrates over its trimmed region (:func:`splinedeform.trim.model_matrices.project`,
    ``values`` then gets the points' parameter arrays ``(Q,)``).

    With general weights (:attr:`~splinedeform.Surface.net_weights`) the basis is
    ``R_kl = w_kl b_k b_l / W``, so ``∫∫ f R_kl = w_kl ∫∫ (f / W) b_k b_l``: the same
    products on ``f / W``, with at least :data:`RATIONAL_POINTS` more points (``1 / W``
    is not a polynomial).
    """
    if surface.trim is not None:
        from .trim.model_matrices import project as project_trimmed

        return project_trimmed(surface, values)
    rational_weights = surface.net_weights
    if rational_weights is not None:
        extra_points = max(extra_points, RATIONAL_POINTS)
    bu, bv = surface.basis_u, surface.basis_v
    xu, wu = gauss_points(bu, bu.degree + 1 + extra_points)
    xv, wv = gauss_points(bv, bv.degree + 1 + extra_points)
    U, V = np.meshgrid(xu, xv, indexing="ij")
    f = np.asarray(values(U, V), dtype=float)
    if f.shape != U.shape + (3,):
        raise InputError(f"a load function must return an array of shape (..., 3) matching "
                         f"its parameter arrays {U.shape}, got {f.shape}")
    if not np.all(np.isfinite(f)):
        raise InputError("a load function returned non-finite values")
    f = f * (wu[:, None] * wv[None, :])[..., None]
    if rational_weights is not None:
        f = f / weight_field(surface, U, V)[..., None]
    Bu, Bv = bu.matrix(xu), bv.matrix(xv)
    tmp = (Bu.T @ f.reshape(xu.size, -1)).reshape(bu.size, xv.size, 3)
    out = Bv.T @ tmp.transpose(1, 0, 2).reshape(xv.size, -1)
    out = np.asarray(out).reshape(bv.size, bu.size, 3).transpose(1, 0, 2).reshape(-1, 3)
    return out if rational_weights is None else out * rational_weights.reshape(-1, 1)


@dataclass(frozen=True)
class Pressure(Load):
    """Pressure ``q`` along the initial normal: ``f = q x0_u × x0_v`` (exact quadrature of
    polynomial directions; :data:`RATIONAL_POINTS` more points where one is rational)."""

    q: float
    profile: Profile = field(default_factory=Constant)

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", _finite(self.q, "Pressure.q"))
        object.__setattr__(self, "profile", _profile(self.profile))

    def field_vector(self, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
        def area_normal(U: NDArray, V: NDArray) -> NDArray:
            return self.q * np.cross(surface.derivative(U, V, 1, 0),
                                     surface.derivative(U, V, 0, 1))
        # integrand degree per direction <= 3n - 1: n + 1 + ceil(n/2) points are exact;
        # a rational direction's integrand is not a polynomial: RATIONAL_POINTS more
        extra = (max(surface.basis_u.degree, surface.basis_v.degree) + 1) // 2
        if any(isinstance(b, RationalBasis) for b in (surface.basis_u, surface.basis_v)):
            extra = max(extra, RATIONAL_POINTS)
        return project(surface, area_normal, extra)


@dataclass(frozen=True)
class Function(Load):
    """A user force field ``f(u, v, t) -> (..., 3)`` per unit parameter area.

    ``f`` receives parameter arrays and a scalar time. Integrated by Gauss quadrature with
    ``2(n+1)`` points per cell (exact for polynomial ``f`` of degree ``<= 3n+1``).
    The analytic solver samples a time-dependent ``f`` piecewise constant in time.
    """

    f: Callable[[NDArray, NDArray, float], ArrayLike]
    profile: Profile = field(default_factory=Constant)
    time_dependent_field: bool = True

    def __post_init__(self) -> None:
        if not callable(self.f):
            raise InputError(f"Function load needs a callable f(u, v, t), got {self.f!r}")
        object.__setattr__(self, "profile", _profile(self.profile))

    def field_vector(self, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
        extra = max(surface.basis_u.degree, surface.basis_v.degree) + 1
        return project(surface, lambda U, V: self.f(U, V, float(t)), extra)


def as_load(load: Load | Iterable[Load] | None) -> Load:
    """Accept a load, a list of loads or ``None`` (no load)."""
    if load is None:
        return LoadSum(())
    if isinstance(load, Load):
        return load
    parts = tuple(load)
    if not all(isinstance(p, Load) for p in parts):
        raise InputError("loads must be Point, Uniform, Pressure or Function objects")
    return LoadSum(parts)


def static_time(load: Load, t: float | None) -> float:
    """The time at which a static solve evaluates ``load``: ``t``, or 0 for a constant load.

    Raises
    ------
    InputError
        When the load varies in time and no ``t`` is given, or ``t`` is not a finite ``>= 0``.
    """
    if t is None:
        if load.time_dependent():
            profiles = sorted({type(term.profile).__name__ for term in load.terms()} - {"Constant"})
            raise InputError(
                f"the load varies in time ({', '.join(profiles)} profile), so a static solve "
                "has no single answer: give the time of the equilibrium wanted, "
                "static(load, t=...), or use a Constant profile")
        return 0.0
    value = _finite(t, "static time t")
    if value < 0:
        raise InputError(f"static time t must be >= 0, got {t}")
    return value


__all__ = ["Constant", "Function", "Harmonic", "Load", "LoadSum", "Piecewise", "Point",
           "Pressure", "Profile", "Step", "Uniform", "as_load", "project", "static_time"]


