"""Closed uniform B-spline trim curves in ``(u, v)``.

``γ(t) = Σ_k P_k b^n(t - k)`` over ``t ∈ [0, K)`` (indices modulo ``K``): on span
``s`` with local ``τ = t - s ∈ [0, 1]`` it is the polynomial
``γ_s(τ) = Σ_{a=0}^{n} P_{s+a} b^n(τ + n - a) = Σ_e C_{s,e} τ^e``, kept in this power form.
Crossings with a line ``u = c`` (or ``v = c``) are the real roots in ``[0, 1)`` of
``x_s(τ) - c``, found for all spans at once as eigenvalues of companion matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..basis import cardinal_bspline
from ..errors import InputError


def _power_matrix(degree: int) -> NDArray[np.float64]:
    """``B[e, a]``: coefficient of ``τ^e`` in ``b^n(τ + n - a)`` (a polynomial on [0, 1])."""
    tau = np.linspace(0.0, 1.0, degree + 1)
    values = cardinal_bspline(tau[:, None] + degree - np.arange(degree + 1), degree)
    return np.linalg.solve(np.vander(tau, degree + 1, increasing=True), values)


def span_roots(coefficients: NDArray[np.float64]) -> NDArray[np.float64]:
    """Real roots in ``[0, 1)`` of polynomials ``Σ_e c_e τ^e`` (rows of ``(S, n+1)``);
    ``(S, n)`` with NaN where there is none. Companion-matrix eigenvalues, vectorised."""
    c = np.asarray(coefficients, dtype=float)
    n = c.shape[1] - 1
    lead = c[:, -1]
    # trailing zero leading coefficients: reduce the degree by scaling a tiny leading term
    scale = np.max(np.abs(c), axis=1)
    safe = np.where(np.abs(lead) > 1e-14 * scale, lead, np.nan)
    companion = np.zeros((len(c), n, n))
    companion[:, 0, :] = -c[:, -2::-1] / safe[:, None]
    if n > 1:
        companion[:, np.arange(1, n), np.arange(n - 1)] = 1.0
    finite = np.all(np.isfinite(companion), axis=(1, 2))
    roots = np.full((len(c), n), np.nan + 0j)
    if np.any(finite):
        roots[finite] = np.linalg.eigvals(companion[finite])
    if np.any(~finite):                        # lower degree: fall back on numpy's roots
        for s in np.flatnonzero(~finite):
            r = np.roots(c[s, ::-1]) if np.any(c[s, 1:]) else np.array([])
            roots[s, :len(r)] = r
    real = np.abs(roots.imag) < 1e-9
    t = roots.real
    # polish with one Newton step on the real polynomial
    with np.errstate(invalid="ignore"):
        p = np.polynomial.polynomial
        for _ in range(2):
            value = np.stack([p.polyval(t[:, j], c.T, tensor=False) for j in range(n)], 1)
            slope = np.stack([p.polyval(t[:, j], (c[:, 1:] * np.arange(1, n + 1)).T,
                                        tensor=False) for j in range(n)], 1)
            step = np.where(np.abs(slope) > 0, value / np.where(slope == 0, 1, slope), 0)
            t = t - np.where(real, step, 0)
    # a root at a span joint belongs to the span it starts (round-off of 1e-15 either side)
    tol = 1e-10
    return np.where(real & (t >= -tol) & (t < 1 - tol), np.clip(t, 0.0, 1.0), np.nan)


@dataclass(frozen=True)
class SplineLoop:
    """A closed uniform B-spline curve of ``degree`` through control points ``(K, 2)``."""

    control_points: NDArray[np.float64]
    degree: int = 3

    def __post_init__(self) -> None:
        P = np.asarray(self.control_points, dtype=float)
        if P.ndim != 2 or P.shape[1] != 2 or P.shape[0] < self.degree + 2:
            raise InputError(f"a degree-{self.degree} spline loop needs at least "
                             f"{self.degree + 2} control points (u, v), got shape {P.shape}")
        if not np.all(np.isfinite(P)):
            raise InputError("spline loop control points must be finite numbers")
        object.__setattr__(self, "control_points", P)
        from .loops import PolygonLoop
        try:
            PolygonLoop(self.sample(32))
        except InputError as error:
            if "intersects itself" not in str(error):
                raise InputError(f"spline loop: {error} (its curve sampled at 32 points per "
                                 "span)") from None
            raise InputError(f"spline loop intersects itself (found on its curve sampled at "
                             f"32 points per span): {error}") from None
        if abs(self.signed_area) <= 1e-14 * np.ptp(P, axis=0).prod():
            raise InputError("a spline loop encloses no area")

    @property
    def spans(self) -> int:
        return len(self.control_points)

    @property
    def power_form(self) -> NDArray[np.float64]:
        """``C[s, e, :]``: power coefficients of span ``s``, shape ``(K, n+1, 2)``."""
        n, K = self.degree, self.spans
        index = (np.arange(K)[:, None] + np.arange(n + 1)) % K
        return np.einsum("ea,sak->sek", _power_matrix(n), self.control_points[index])

    def evaluate(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Points and tangents at curve parameters ``t`` (any shape)."""
        t = np.mod(np.asarray(t, dtype=float), self.spans)
        s = np.minimum(t.astype(int), self.spans - 1)
        tau = t - s
        C = self.power_form[s]                          # (..., n+1, 2)
        e = np.arange(self.degree + 1)
        powers = tau[..., None] ** e
        dpowers = np.where(e > 0, e * tau[..., None] ** np.maximum(e - 1, 0), 0.0)
        return (np.einsum("...e,...ek->...k", powers, C),
                np.einsum("...e,...ek->...k", dpowers, C))

    def sample(self, per_span: int) -> NDArray[np.float64]:
        return self.evaluate(np.arange(self.spans * per_span) / per_span)[0]

    @property
    def signed_area(self) -> float:
        """``½ ∮ (x y' - y x') dt`` by Gauss with ``n + 1`` points per span (exact:
        degree ``2n - 1``)."""
        xi, w = np.polynomial.legendre.leggauss(self.degree + 1)
        t = (np.arange(self.spans)[:, None] + 0.5 * (xi + 1)).ravel()
        p, d = self.evaluate(t)
        return 0.25 * float(np.sum(np.tile(w, self.spans) * (p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0])))

    def oriented(self, counter_clockwise: bool) -> "SplineLoop":
        if (self.signed_area > 0) == counter_clockwise:
            return self
        return SplineLoop(self.control_points[::-1].copy(), self.degree)

    def crossings(self, axis: int, value: float) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Spans and local ``τ`` where coordinate ``axis`` of the curve equals ``value``."""
        c = self.power_form[:, :, axis].copy()
        c[:, 0] -= value
        tau = span_roots(c)
        span, k = np.nonzero(np.isfinite(tau))
        return span, tau[span, k]

    def encloses(self, p: ArrayLike) -> NDArray[np.bool_]:
        """Crossing number of a ray from each point with the exact curve.

        The ray leaves in the direction ``(cos 1, sin 1)``, no grid or symmetry direction, so
        that it meets span joints and tangent points only by accident of measure zero.
        """
        p = np.asarray(p, dtype=float)
        flat = p.reshape(-1, 2)
        K, n = self.spans, self.degree
        ray = np.array([np.cos(1.0), np.sin(1.0)])
        normal = np.array([-ray[1], ray[0]])
        C = np.stack([self.power_form @ ray, self.power_form @ normal], axis=-1)
        flat = np.stack([flat @ ray, flat @ normal], axis=-1)
        c = np.broadcast_to(C[None, :, :, 1], (len(flat), K, n + 1)).copy()
        c[:, :, 0] -= flat[:, 1, None]
        tau = span_roots(c.reshape(-1, n + 1)).reshape(len(flat), K, n)
        x = np.einsum("psre,se->psr", np.nan_to_num(tau)[..., None] ** np.arange(n + 1),
                      C[:, :, 0])
        hits = np.isfinite(tau) & (x > flat[:, 0, None, None])
        return (hits.sum(axis=(1, 2)) % 2 == 1).reshape(p.shape[:-1])

    def distance(self, p: ArrayLike) -> NDArray[np.float64]:
        """Distance to the curve: nearest of 64 samples per span, then Newton steps on
        ``(γ(t) - p)·γ'(t) = 0`` (second derivative from a central difference)."""
        p = np.asarray(p, dtype=float)
        flat = p.reshape(-1, 2)
        grid = np.arange(self.spans * 64) / 64
        samples = self.evaluate(grid)[0]
        gap = flat[:, None] - samples[None]
        t = grid[np.argmin(np.sum(gap * gap, axis=-1), axis=1)]
        e = 1e-6
        for _ in range(4):
            q, d = self.evaluate(t)
            _, d2p = self.evaluate(t + e)
            _, d2m = self.evaluate(t - e)
            dd = (d2p - d2m) / (2 * e)
            g = np.sum((q - flat) * d, axis=1)
            gp = np.sum(d * d, axis=1) + np.sum((q - flat) * dd, axis=1)
            t = t - np.clip(g / np.where(gp > 0, gp, np.inf), -1 / 64, 1 / 64)
        q = self.evaluate(t)[0]
        return np.hypot(*(q - flat).T).reshape(p.shape[:-1])

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.control_points.min(axis=0), self.control_points.max(axis=0)
