"""Solutions: the deformed control net, surface and energies at any requested time.

A solution holds its state in the reduced (free) coordinates ``d_free`` of the constraint
map ``d = T d_free`` and a :class:`Readout` (the rest surface, ``T`` and the reduced ``M``,
``K``), not the model; control points are ``p(t) = p_rest + T d_free(t)`` (three coordinates
share ``T``). Energies follow DESIGN.md §1.4: kinetic ``½ Σ_c v_cᵀ M v_c``, strain
``½ Σ_c d_cᵀ K d_c``, work of the current load ``Σ_c F_c(t)ᵀ d_c`` and
``total = kinetic + strain - work`` (conserved for a constant load without damping).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from .errors import InputError
from .readout import BodyReadout, Readout  # noqa: F401 (Readout: public here)
from .surface import Surface
from .threads import owned

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Energy:
    """Energies at the requested times (arrays of the times' shape)."""

    kinetic: Array
    strain: Array
    work: Array

    @property
    def total(self) -> Array:
        """``kinetic + strain - work``."""
        return self.kinetic + self.strain - self.work


@dataclass(frozen=True)
class Frames:
    """Many frames of a solution (see :meth:`Solution.frames`).

    Attributes
    ----------
    times : ndarray (F,)
    control_points : ndarray (F, n_u, n_v, 3)
        (a body's: a list of them, one per patch)
    points : ndarray (F, r_u, r_v, 3) or None
        Surface samples on the parameter grid, when a resolution was asked for (a body's:
        a list, one per patch).
    """

    times: Array
    control_points: Any
    points: Any


def _check_times(t: ArrayLike, t_end: float | None = None) -> tuple[Array, bool]:
    arr = np.asarray(t, dtype=float)
    if arr.ndim > 1:
        raise InputError(f"times must be a number or a 1-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError("times must be finite")
    if np.any(arr < 0):
        raise InputError(f"times must be >= 0, got {arr.min():g}")
    if t_end is not None and np.any(arr > t_end * (1 + 1e-12)):
        raise InputError(f"this numerical solution covers [0, {t_end:g}]; got t = {arr.max():g}")
    return np.atleast_1d(arr), arr.ndim == 0


class _Displaced:
    """Shared read-out of a state in free coordinates."""

    readout: Readout | BodyReadout

    @property
    def rest(self) -> Any:
        """The rest surface the displacements are added to (a body's: its patches)."""
        surfaces = getattr(self.readout, "surfaces", None)
        return self.readout.surface if surfaces is None else surfaces

    def _full(self, d_free: Array, rest: bool = True) -> Any:
        """``[p_rest +] T d_free`` for ``d_free`` of shape ``(..., n_free, 3)`` →
        ``(..., n_u, n_v, 3)`` (a body's: a list of them, one per patch)."""
        return self.readout.nets(d_free, rest)


class StaticSolution(_Displaced):
    """Equilibrium ``K d = F`` of a model under a load (see :meth:`Model.static`)."""

    def __init__(self, readout: Readout, d_free: Array, force_free: Array,
                 timings: dict[str, float]):
        self.readout = readout
        self.d_free = d_free
        self.force_free = force_free
        self.timings = timings

    @owned
    def control_points(self) -> Array:
        """Deformed control net ``(n_u, n_v, 3)``."""
        return self._full(self.d_free)

    def surface(self) -> Any:
        """The deformed surface (a body's: a list of its deformed patches)."""
        return self.readout.deformed(self.control_points(), "static")

    @owned
    def displacement(self, u: ArrayLike, v: ArrayLike, patch: int | None = None) -> Array:
        """Displacement ``d(u, v)`` of surface points, shape ``S + (3,)`` (of ``patch`` for
        a body)."""
        rest, net = self.readout.patch(self._full(self.d_free, rest=False), patch)
        return rest.derivative(u, v, control_points=net)

    def net_displacement(self) -> Any:
        """Displacement of the control points ``(n_u, n_v, 3)`` (a body's: one per patch)."""
        return self._full(self.d_free, rest=False)

    def stresses(self, u: ArrayLike, v: ArrayLike, patch: int | None = None) -> Any:
        """Resultants, stresses and von Mises at ``(u, v)`` (of ``patch`` on a body), where
        the physics has them (:mod:`splinedeform.physics.shell_stress`)."""
        return self.readout.stresses(self.net_displacement(), u, v, patch=patch)

    @owned
    def energy(self) -> Energy:
        K = self.readout.K
        strain = 0.5 * np.sum(self.d_free * (K @ self.d_free))
        work = np.sum(self.force_free * self.d_free)
        return Energy(np.array(0.0), np.array(strain), np.array(work))


class Solution(_Displaced):
    """Motion of the control net; subclasses provide the state in free coordinates.

    Attributes
    ----------
    method : str
    t_end : float
    timings : dict
        Seconds spent per stage (``assembly``, ``eigen``, ``integration``, …).
    """

    exact_between_frames = True

    def __init__(self, readout: Readout, method: str, t_end: float,
                 force_free: Callable[[float], Array], timings: dict[str, float]):
        self.readout = readout
        self.method = method
        self.t_end = float(t_end)
        self._force_free = force_free
        self.timings = timings
        self._grid_matrices: dict = {}

    @owned
    def state(self, t: ArrayLike) -> tuple[Array, Array]:
        """Free displacements and velocities at times ``t`` (F,), each ``(F, n_free, 3)``
        (one unknown per control point) or ``(F, n_free)`` (three, :mod:`.readout`)."""
        raise NotImplementedError

    @owned
    def control_points(self, t: ArrayLike) -> Array:
        """Control net at ``t``: ``(n_u, n_v, 3)`` for a number, ``(F, n_u, n_v, 3)`` for an array."""
        times, scalar = _check_times(t)
        nets = self._full(self.state(times)[0])
        return _first(nets) if scalar else nets

    @owned
    def velocities(self, t: ArrayLike) -> Array:
        """Control point velocities, same shapes as :meth:`control_points`."""
        times, scalar = _check_times(t)
        vel = self._full(self.state(times)[1], rest=False)
        return _first(vel) if scalar else vel

    def surface(self, t: float) -> Any:
        """The deformed surface at time ``t`` (a body's: a list of its deformed patches)."""
        return self.readout.deformed(self.control_points(float(t)), f"t={float(t):g}")

    @owned
    def displacement(self, t: ArrayLike, u: ArrayLike, v: ArrayLike,
                     patch: int | None = None) -> Array:
        """Displacement of surface points: ``S + (3,)`` for scalar ``t``, ``(F,) + S + (3,)``
        else (of ``patch`` for a body)."""
        times, scalar = _check_times(t)
        rest, nets = self.readout.patch(self.control_points(times), patch)
        nets = nets - rest.control_points
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        E = rest.evaluation_matrix(u, v)
        flat = np.moveaxis(nets.reshape(times.size, -1, 3), 0, 1).reshape(E.shape[1], -1)
        out = np.moveaxis((E @ flat).reshape(E.shape[0], times.size, 3), 1, 0)
        out = out.reshape((times.size,) + u.shape + (3,))
        return out[0] if scalar else out

    @owned
    def frames(self, times: ArrayLike, resolution: int | tuple[int, int] | None = None
               ) -> Frames:
        """Control nets at many times and, with ``resolution``, the surface sampled per frame.

        The samples on the ``r_u × r_v`` parameter grid of
        :meth:`~splinedeform.Surface.sample_parameters` are ``X_f = E P_f`` with the sparse
        evaluation matrix ``E_{(i,j),(k,l)} = b_k(u_i) b_l(v_j)``, built once per resolution
        and applied to all frames and coordinates in one sparse product.
        """
        times_arr, _ = _check_times(times)
        nets = self.control_points(times_arr)
        if resolution is None:
            return Frames(times_arr, nets, None)
        key = resolution if np.isscalar(resolution) else tuple(resolution)
        if isinstance(nets, list):          # a body: each patch on its own grid
            points = [self._sampled(surf, net, key, i)
                      for i, (surf, net) in enumerate(zip(self.rest, nets))]
        else:
            points = self._sampled(self.rest, nets, key, 0)
        return Frames(times_arr, nets, points)

    def _sampled(self, surf: Surface, nets: Array, key: Any, index: int) -> Array:
        """Samples ``(F, r_u, r_v, 3)`` of the nets ``(F, n_u, n_v, 3)`` of one surface."""
        cache = self._grid_matrices
        if (key, index) not in cache:
            u, v = surf.sample_parameters(key)
            cache[key, index] = (surf.evaluation_matrix(u[:, None], v[None, :]), u.size, v.size)
        E, ru, rv = cache[key, index]
        count = nets.shape[0]
        flat = np.moveaxis(nets.reshape(count, -1, 3), 0, 1).reshape(E.shape[1], -1)
        return np.moveaxis(np.asarray(E @ flat).reshape(ru, rv, count, 3), 2, 0)

    def stresses(self, t: float, u: ArrayLike, v: ArrayLike, patch: int | None = None) -> Any:
        """Resultants, stresses and von Mises at time ``t`` (a number) and ``(u, v)`` (of
        ``patch`` on a body), where the physics has them."""
        times, scalar = _check_times(t)
        if not scalar:
            raise InputError(f"stresses are read at one time at a time, got {times.size} times")
        net = self._full(self.state(times)[0], rest=False)
        net = [n[0] for n in net] if isinstance(net, list) else net[0]
        return self.readout.stresses(net, u, v, patch=patch)

    @owned
    def energy(self, t: ArrayLike) -> Energy:
        """Kinetic, strain and load-work energies at ``t`` (see the module docstring)."""
        times, scalar = _check_times(t)
        M, K = self.readout.M, self.readout.K
        d, v = self.state(times)
        kinetic = 0.5 * _quadratic(M, v)
        strain = 0.5 * _quadratic(K, d)
        work = np.array([np.sum(np.reshape(self._force_free(ti), di.shape) * di)
                         for ti, di in zip(times, d)])
        if scalar:
            return Energy(kinetic[0], strain[0], work[0])
        return Energy(kinetic, strain, work)


def _first(nets: Any) -> Any:
    """The first frame of nets ``(F, ...)`` (of each patch's for a body)."""
    return [n[0] for n in nets] if isinstance(nets, list) else nets[0]


def _quadratic(A: sp.spmatrix, x: Array) -> Array:
    """``Σ_c x_cᵀ A x_c`` for each frame of ``x`` (F, n, 3), or ``xᵀ A x`` of (F, n)."""
    F, n = x.shape[:2]
    flat = np.moveaxis(x.reshape(F, n, -1), 1, 0).reshape(n, -1)
    return np.sum(flat * (A @ flat), axis=0).reshape(F, -1).sum(axis=1)


class SampledSolution(Solution):
    """Numerical solution stored at output times; cubic Hermite in between."""

    exact_between_frames = False

    def __init__(self, readout: Readout, method: str, t_end: float,
                 force_free: Callable[[float], Array], timings: dict[str, float],
                 times: Array, d: Array, v: Array, stats: dict):
        super().__init__(readout, method, t_end, force_free, timings)
        self.times, self.d, self.v = times, d, v
        self.stats = stats

    @owned
    def state(self, t: ArrayLike) -> tuple[Array, Array]:
        times, _ = _check_times(t, self.t_end)
        i = np.clip(np.searchsorted(self.times, times, side="right") - 1, 0,
                    max(len(self.times) - 2, 0))
        if len(self.times) == 1:
            return self.d[[0] * times.size], self.v[[0] * times.size]
        t0, t1 = self.times[i], self.times[i + 1]
        h = (t1 - t0)[:, None, None]
        s = ((times - t0) / (t1 - t0))[:, None, None]
        d0, d1, v0, v1 = self.d[i], self.d[i + 1], self.v[i], self.v[i + 1]
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
        d = h00 * d0 + h10 * h * v0 + h01 * d1 + h11 * h * v1
        dv = ((6 * s**2 - 6 * s) * d0 + (3 * s**2 - 4 * s + 1) * h * v0
              + (-6 * s**2 + 6 * s) * d1 + (3 * s**2 - 2 * s) * h * v1) / h
        return d, dv
