"""Solutions of the Kirchhoff–Love shell, read out like those of the scalar models.

The state lives in the shell's reduced unknowns ``d_free`` (x, y and z coupled, one column
of ``T`` per free displacement component); control points are
``p(t) = p_rest + reshape(T d_free(t))``. Energies as for :mod:`splinedeform.solution`:
kinetic ``½ vᵀ M_r v``, strain ``½ dᵀ K_r d``, work of the current load ``F(t)ᵀ d`` and
``total = kinetic + strain − work``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..readout import BodyReadout
from ..solution import Energy, Solution, _check_times
from ..surface import Surface

if TYPE_CHECKING:
    from .shell_model import ShellModel
    from .shell_stress import ShellStresses

Array = NDArray[np.float64]


def _full(model: ShellModel, d_free: Array) -> Array | list[Array]:
    """``p_rest + T d_free`` for ``d_free`` of shape ``(..., n_free)`` → ``(..., n_u, n_v, 3)``
    (a body's: a list, one per patch)."""
    nets = model.nets(d_free)
    if model.patches is None:
        return model.surface.control_points + nets
    return [s.control_points + n for s, n in zip(model.patches, nets)]


class ShellStaticSolution:
    """Equilibrium ``K_r d = Tᵀ F`` of a shell (see :meth:`ShellModel.static`).

    On a body every net and surface is a list, one per patch, and a read-out at ``(u, v)``
    names its ``patch``.
    """

    def __init__(self, model: ShellModel, d_free: Array, force_free: Array,
                 timings: dict[str, float]):
        self.model = model
        self.d_free = d_free
        self.force_free = force_free
        self.timings = timings

    def control_points(self) -> Array | list[Array]:
        """Deformed control net ``(n_u, n_v, 3)``."""
        return _full(self.model, self.d_free)

    def net_displacement(self) -> Array | list[Array]:
        """Displacement of the control points ``(n_u, n_v, 3)``."""
        return self.model.nets(self.d_free)

    def surface(self) -> Surface | list[Surface]:
        """The deformed surface."""
        if self.model.patches is None:
            return self.model.surface.with_control_points(self.control_points(), name="static")
        return [s.with_control_points(p, name="static")
                for s, p in zip(self.model.patches, self.control_points())]

    def displacement(self, u: ArrayLike, v: ArrayLike, patch: int | None = None) -> Array:
        """Displacement ``d(u, v)`` of surface points, shape ``S + (3,)``."""
        if self.model.patches is None:
            return self.model.surface.derivative(u, v, control_points=self.net_displacement())
        p = self.model.patch_index(patch)
        return self.model.patches[p].derivative(u, v,
                                                control_points=self.net_displacement()[p])

    def stresses(self, u: ArrayLike, v: ArrayLike, patch: int | None = None) -> ShellStresses:
        """Resultants ``N, M``, stresses and von Mises at ``(u, v)`` (:mod:`.shell_stress`)."""
        return self.model.stresses(self.net_displacement(), u, v, patch=patch)

    def energy(self) -> Energy:
        """Strain ``½ dᵀ K_r d``, load work ``Fᵀ d`` (total ``−½ Fᵀ d`` at equilibrium)."""
        K = self.model.matrices()[2]
        strain = 0.5 * float(self.d_free @ (K @ self.d_free))
        work = float(self.force_free @ self.d_free)
        return Energy(np.array(0.0), np.array(strain), np.array(work))


class ShellModalSolution(Solution):
    """Closed-form motion of a shell: ``d_free(t) = Φ Q(t)`` (+ static correction).

    ``Q(t)`` comes from :class:`~splinedeform.solvers.analytic.ModalResponse` with one
    column; ``correction(t)`` is the mode-acceleration part of the modes a truncated basis
    leaves out (``None`` for a complete basis).
    """

    def __init__(self, model: Any, t_end: float, force_free: Callable[[float], Array],
                 timings: dict[str, float], basis: Any, response: Any, truncation: dict,
                 correction: Callable[[Array], Array] | None = None):
        # a single shell reads out like a surface (.surface); a body like BodyModel's, on
        # the per-patch nets of ``_full`` below
        readout = model if model.patches is None else BodyReadout(
            model.patches, model.T, *model.matrices()[::2])
        super().__init__(readout, "analytic", t_end, force_free, timings)
        self.model = model
        self.basis = basis
        self.response = response
        self.truncation = truncation
        self.correction = correction

    def _full(self, d_free: Array) -> Array:
        return _full(self.model, d_free)

    def state(self, t: ArrayLike) -> tuple[Array, Array]:
        """Free displacements and velocities at times ``t`` (F,), each ``(F, n_free)``."""
        times, _ = _check_times(t)
        Q, V = self.response(times)
        d = self.basis.expand(Q)[..., 0]
        if self.correction is not None:
            d = d + self.correction(times)[..., 0]
        return d, self.basis.expand(V)[..., 0]

    def stresses(self, t: float, u: ArrayLike, v: ArrayLike, patch: int | None = None
                 ) -> ShellStresses:
        """Resultants, stresses and von Mises at time ``t`` (a number) and ``(u, v)`` (of
        ``patch`` on a body)."""
        times, scalar = _check_times(t)
        if not scalar:
            raise InputError(f"stresses are read at one time at a time, got {times.size} times")
        net = self.model.nets(self.state(times)[0])
        net = net[0] if self.model.patches is None else [n[0] for n in net]
        return self.model.stresses(net, u, v, patch=patch)

    def velocities(self, t: ArrayLike) -> Array:
        """Control point velocities, same shapes as :meth:`control_points`."""
        times, scalar = _check_times(t)
        vel = self.model.nets(self.state(times)[1])
        if self.model.patches is not None:
            return [n[0] for n in vel] if scalar else vel
        return vel[0] if scalar else vel

    def energy(self, t: ArrayLike) -> Energy:
        """Kinetic, strain and load-work energies at ``t`` (see the module docstring)."""
        times, scalar = _check_times(t)
        M, _, K = self.model.matrices()
        d, v = self.state(times)
        kinetic = 0.5 * np.einsum("fi,fi->f", v, (M @ v.T).T)
        strain = 0.5 * np.einsum("fi,fi->f", d, (K @ d.T).T)
        work = np.array([self._force_free(ti) @ di for ti, di in zip(times, d)])
        if scalar:
            return Energy(kinetic[0], strain[0], work[0])
        return Energy(kinetic, strain, work)
