"""The analytic solution: ``d_free(t) = Φ Q(t)`` with closed-form modal coordinates, read
out frame chunk by frame chunk (:class:`ModalSolution`; the other solutions and the read-out
are in :mod:`splinedeform.solution`)."""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .readout import Readout
from .solution import Solution, _check_times, _first
from .solvers.bases import DenseBasis, ModalBasis
from .solvers.products import selected_rows
from .threads import owned

Array = NDArray[np.float64]


class ModalSolution(Solution):
    """Analytic solution: ``d_free(t) = Φ Q(t)`` with closed-form modal coordinates.

    ``Φ`` is a :class:`~splinedeform.solvers.modal_basis.ModalBasis` (an explicit matrix is
    accepted too); a truncated basis adds the mode-acceleration ``correction(t)`` and reports
    its truncation in ``truncation`` (see :meth:`splinedeform.Model.dynamic`). Times are
    processed in chunks of about :attr:`chunk_entries` modal values so that many frames of a
    large net fit in memory. ``accuracy`` (automatic mode count) keeps every time asked
    within its tolerance: times where the basis' bound exceeds it (just after a load jump)
    come from :attr:`finer`, a solution whose modes are chosen for them
    (:class:`splinedeform.modal_solve.Accuracy`); the other times keep the cheaper basis.
    """

    chunk_entries = 4_000_000

    def __init__(self, readout: Readout, t_end: float, force_free: Callable[[float], Array],
                 timings: dict[str, float], phi: Any, response: Callable, omitted: dict,
                 correction: Callable[[Array], Array] | None = None, accuracy: Any = None):
        super().__init__(readout, "analytic", t_end, force_free, timings)
        self.basis = phi if isinstance(phi, ModalBasis) else DenseBasis(response.lam, phi)
        self.response = response
        self.truncation = omitted
        self.correction = correction
        self.accuracy = accuracy
        self.finer: ModalSolution | None = None
        """The solution chosen for the first times asked where ``accuracy``'s bound missed;
        it serves every such time (choosing its own finer one when its bound misses)."""

    @property
    def phi(self) -> Array:
        """The modes as an explicit ``(n_free, N)`` matrix (formed on demand for structured bases)."""
        return self.basis.columns(np.arange(self.basis.size))

    def _chunks(self, times: Array) -> list[Array]:
        per = max(1, self.chunk_entries // max(3 * self.basis.size, 1))
        return [times[i:i + per] for i in range(0, times.size, per)] or [times]

    def _displacements(self, times: Array, velocities: bool) -> tuple[Array, Array | None]:
        """``d`` (and ``v``) at ``times``; with an ``accuracy`` (automatic mode count), the
        times where its bound exceeds the tolerance come from a solution chosen for them."""
        if self.accuracy is not None:
            finer = self.accuracy.outside(times)
            if np.any(finer):
                d, v = self._own(times, velocities)
                if self.finer is None:
                    self.finer = self.accuracy.refine(times[finer])
                d[finer], v_finer = self.finer._displacements(times[finer], velocities)
                if v is not None and v_finer is not None:
                    v[finer] = v_finer
                return d, v
        return self._own(times, velocities)

    def _own(self, times: Array, velocities: bool,
             into: tuple[Array, Array] | None = None) -> tuple[Array, Array | None]:
        """``d`` (and ``v``) at ``times`` from this solution's own basis and correction;
        with ``into = (full, rows)`` ``d`` is ``full`` ``(F, n_points, columns)``, the free
        unknowns' rows ``rows`` filled (:meth:`_direct`)."""
        n, columns = self.basis.n_free, self.readout.columns
        d = np.zeros((times.size, n, columns)) if into is None else into[0]
        v = np.zeros((times.size, n, columns)) if velocities else None
        active = getattr(self.response, "active", np.arange(columns))   # columns that move
        early = self._early(active)
        i = 0
        for part in self._chunks(times):
            span = slice(i, i + part.size)
            if active.size:
                if hasattr(self.response, "active_part"):
                    Q, V = self.response.active_part(part)
                else:
                    Q, V = self.response(part)
                expanded = self.basis.expand(Q)
                if early:
                    if not expanded.flags.writeable:
                        expanded = expanded.copy()
                    self.correction.add_to(part, expanded, columns=active)
                if into is None:
                    d[span, :, active] = expanded
                else:
                    d[span][:, into[1][:, None], active] = expanded
                if v is not None:
                    v[span, :, active] = self.basis.expand(V)
            if self.correction is not None and not early:
                add = getattr(self.correction, "add_to", None)     # in place, if it can
                if add is not None:
                    add(part, d[span])
                else:
                    d[span] += self.correction(part)
            i += part.size
        return d, v

    @owned
    def state(self, t: ArrayLike) -> tuple[Array, Array]:
        times, _ = _check_times(t)
        d, v = self._displacements(times, True)
        assert v is not None
        return self.readout.from_columns(d), self.readout.from_columns(v)

    def _early(self, active: Array) -> bool:
        """Whether the correction is one in some coordinates only (the transient one), all
        ``active``: it is then added to the modal expansion in place, before ``d``."""
        moving = getattr(self.correction, "moving", None)
        return moving is not None and active.size > 0 and bool(np.isin(moving, active).all())

    def _direct(self, times: Array) -> Array | None:
        """Nets ``p_rest + T d`` without storing ``d`` (at 128², 200 frames: 77 MB) where
        ``T`` selects points (:func:`~.solvers.products.selected_rows`), every time is this
        solution's own and no correction is left for ``d``: the expansion goes straight
        into the free points' rows; ``None`` elsewhere (then :meth:`_displacements`)."""
        readout = self.readout
        if not isinstance(readout, Readout) or readout.per_point != 1:
            return None
        rows = selected_rows(readout.T)
        active = getattr(self.response, "active", np.arange(readout.columns))
        if rows is None or not (self.correction is None or self._early(active)):
            return None
        if self.accuracy is not None and np.any(self.accuracy.outside(times)):
            return None
        full = np.zeros((times.size, readout.T.shape[0], readout.columns))
        self._own(times, False, into=(full, rows))
        nets = full.reshape((times.size,) + readout.surface.shape + (3,))
        nets += readout.surface.control_points
        return nets

    @owned
    def control_points(self, t: ArrayLike) -> Array:
        """Control net at ``t``: ``(n_u, n_v, 3)`` for a number, ``(F, n_u, n_v, 3)`` for an array."""
        times, scalar = _check_times(t)
        nets = self._direct(times)
        if nets is None:
            nets = self._full(self.readout.from_columns(self._displacements(times, False)[0]))
        return _first(nets) if scalar else nets

    def modal(self, t: ArrayLike) -> tuple[Array, Array]:
        """Modal coordinates ``Q(t), Q'(t)``, each ``(F, N, 3)``."""
        return self.response(_check_times(t)[0])
