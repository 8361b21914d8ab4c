"""Tensor-product B-spline surfaces ``x(u,v) = Σ_k Σ_l p_kl b_k(u) b_l(v)``.

A :class:`Surface` composes two :class:`~splinedeform.basis.BSplineBasis` objects; all
evaluation goes through them (no second evaluator). The control net is stored as an
array ``(n_u, n_v, 3)`` and flattened row-major (``k`` over u, ``l`` over v), so a
tensor-product operator on the flattened net is ``A_u ⊗ A_v``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from .basis import BSplineBasis
from .collocation import collocate
from .deboor import BLOCK
from .patches import evaluate_patch_point, evaluate_patches, patches_when_worth
from .spans import scalar_bernstein
from .errors import InputError
from .knots import KnotVectorBasis, RationalBasis
from . import rational

#: the 1-D bases a surface composes: the fast layouts, a general knot vector, a weighted one
Basis = BSplineBasis | KnotVectorBasis | RationalBasis


_SCALARS = (float, int, np.float64)
_POINTS = ("patches", 0, 0)


def _has_span_form(basis: Basis) -> bool:
    return getattr(basis, "form", None) is not None


def span_values(basis: Basis, span: int, s: float, derivative: int) -> NDArray[np.float64]:
    """``D^j`` of the ``n + 1`` functions of one span at local parameter ``s`` (a float)."""
    return basis.form.coefficients[derivative][span] @ np.array(
        scalar_bernstein(s, basis.degree - derivative))


def span_indices(basis: Basis, span: int) -> NDArray[np.int64]:
    """Indices of the ``n + 1`` functions not vanishing on one span."""
    n = basis.degree
    if basis.kind == "periodic":
        return (span - n + np.arange(n + 1)) % basis.cells
    first = basis.first[span] if basis.kind == "general" else span
    return first + np.arange(n + 1)


def _order(order: object) -> bool:
    """Whether ``order`` is a valid derivative order (else the general path says why not)."""
    return isinstance(order, (int, np.integer)) and not isinstance(order, bool) and order >= 0


#: largest number of sample points ``ru * rv`` of one tessellation (2048², about 300 MiB
#: of vertices and faces)
MAX_SAMPLES = 2048 * 2048


@dataclass(frozen=True)
class Surface:
    """A B-spline surface on the parameter rectangle ``[0, L_u] × [0, L_v]``.

    Parameters
    ----------
    control_points : array_like, shape ``(n_u, n_v, 3)``
        The control net; ``n_u = basis_u.size`` and ``n_v = basis_v.size``.
    basis_u, basis_v : BSplineBasis, KnotVectorBasis or RationalBasis
        The bases in the two parameter directions. A general knot vector must start its
        domain at 0 (``t_n = 0``; see :meth:`KnotVectorBasis.shifted`). Two rational bases
        with weights ``a_k`` and ``b_l`` make the NURBS surface with weights ``a_k b_l``.
    net_weights : array_like, shape ``(n_u, n_v)``, optional
        General NURBS weights ``w_kl`` on polynomial bases, for weights that are not a
        product: the basis is ``R_kl = w_kl N_k N_l / Σ w N N`` (:mod:`splinedeform.rational`).
    fit_error : float or None
        Maximum distance to the map the net was fitted to (set by :mod:`splinedeform.shapes`).
    name : str
        A label used in reports.
    trim : TrimDomain or None
        The trimmed region in ``(u, v)`` (:mod:`splinedeform.trim`); ``None``: the whole
        rectangle. Set by :meth:`with_trim`.
    orientation : {1, -1}
        The side a pressure pushes towards: ``orientation · x_u × x_v``. ``-1`` for a CAD
        face its Brep marks reversed (its outward normal is ``-(x_u × x_v)``); the
        parameters stay as they are. A body's default
        (:attr:`splinedeform.body.Body.orientation`).
    """

    control_points: NDArray[np.float64]
    basis_u: Basis
    basis_v: Basis
    fit_error: float | None = None
    name: str = "surface"
    trim: Any = None
    net_weights: NDArray[np.float64] | None = None
    orientation: int = 1
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name, basis in (("u", self.basis_u), ("v", self.basis_v)):
            start = getattr(basis, "domain", (0.0,))[0]
            if start != 0.0:
                raise InputError(f"the parameter domain in {name} must start at 0, got a knot "
                                 f"vector starting its domain at {start:g}; shift it "
                                 "(KnotVectorBasis.shifted)")
        if np.iscomplexobj(self.control_points):
            raise InputError("control points are complex; a surface is real (take .real "
                             "explicitly if the imaginary part is meant to go)")
        P = np.array(self.control_points, dtype=float)
        expected = (self.basis_u.size, self.basis_v.size, 3)
        if P.shape != expected:
            raise InputError(f"control net must have shape {expected} (n_u, n_v, 3) for these "
                             f"bases, got {P.shape}")
        if not np.all(np.isfinite(P)):
            bad = np.argwhere(~np.isfinite(P))[0]
            raise InputError(f"control points must be finite; control point "
                             f"{tuple(int(i) for i in bad[:2])} is {P[tuple(bad[:2])]}")
        P.setflags(write=False)
        object.__setattr__(self, "control_points", P)
        if self.net_weights is not None:
            self._check_net_weights()
        if isinstance(self.orientation, bool) or self.orientation not in (1, -1):
            raise InputError(f"orientation must be +1 or -1, got {self.orientation!r}")
        object.__setattr__(self, "orientation", int(self.orientation))

    def _check_net_weights(self) -> None:
        """General weights: one per control point, > 0, on polynomial bases."""
        if any(isinstance(b, RationalBasis) for b in (self.basis_u, self.basis_v)):
            raise InputError("give NURBS weights either per direction (rational bases) or "
                             "per control point (net_weights), not both")
        for name, basis in (("u", self.basis_u), ("v", self.basis_v)):
            if not rational.clamped(basis):
                raise InputError(f"net_weights need knot vectors clamped at both ends (or "
                                 f"periodic); direction {name} is not: on an unclamped end "
                                 "the edge conditions would mix the weights of several rows")
        object.__setattr__(self, "net_weights", rational.check_weights(self.net_weights,
                                                                       self.shape))

    def __repr__(self) -> str:
        """One line: name, net size, degrees, knot layouts, domain (never the net itself)."""
        (_, lu), (_, lv) = self.domain
        fit = "" if self.fit_error is None else f", fit_error={self.fit_error:.3g}"
        fit += "" if self.net_weights is None else ", general weights"
        return (f"Surface({self.name!r}, {self.shape[0]}×{self.shape[1]} control points, "
                f"degree=({self.basis_u.degree}, {self.basis_v.degree}), "
                f"knots=({knots_summary(self.basis_u)}, {knots_summary(self.basis_v)}), "
                f"domain=[0, {lu:.6g}] × [0, {lv:.6g}]{fit})")

    # -- layout ---------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """Control net size ``(n_u, n_v)``."""
        return self.basis_u.size, self.basis_v.size

    @property
    def domain(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Parameter rectangle ``((0, L_u), (0, L_v))``."""
        return (0.0, self.basis_u.length), (0.0, self.basis_v.length)

    @property
    def weights(self) -> NDArray[np.float64]:
        """NURBS weights of the net: :attr:`net_weights`, else ``w_kl = a_k b_l`` (``a``, ``b``
        of rational directions, 1 else)."""
        if self.net_weights is not None:
            return self.net_weights
        a, b = (np.asarray(basis.weights) if isinstance(basis, RationalBasis)
                else np.ones(basis.size) for basis in (self.basis_u, self.basis_v))
        return np.outer(a, b)

    def with_control_points(self, control_points: ArrayLike, name: str | None = None) -> Surface:
        """The same bases with another control net (``fit_error`` dropped)."""
        return replace(self, control_points=control_points, fit_error=None,
                       name=self.name if name is None else name)

    def with_trim(self, domain: Any) -> Surface:
        """The same surface trimmed to ``domain`` (a :class:`~splinedeform.trim.TrimDomain`
        inside the parameter rectangle), or untrimmed for ``None``."""
        from .trim.surface_trim import checked_trim

        return replace(self, trim=None if domain is None else checked_trim(self, domain))

    # -- evaluation -------------------------------------------------------------
    def evaluation_matrix(self, u: ArrayLike, v: ArrayLike, du: int = 0, dv: int = 0
                          ) -> sp.csr_matrix:
        """Sparse ``E`` with ``∂^{du+dv} x / ∂u^du ∂v^dv (u_i, v_i) = (E @ P.reshape(-1, 3))_i``.

        ``E_{i, k n_v + l} = D^{du} b_k(u_i) D^{dv} b_l(v_i)``; ``u`` and ``v`` are
        flattened after broadcasting to a common shape. With :attr:`net_weights`, the
        rational ``D^(du,dv) R_kl`` (:func:`splinedeform.rational.evaluation_matrix`).
        """
        if self.net_weights is not None:
            return rational.evaluation_matrix(self, u, v, du, dv)
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        u, v = u.ravel(), v.ravel()
        iu, bu = self.basis_u.nonzero(u, du)
        iv, bv = self.basis_v.nonzero(v, dv)
        values = bu[:, :, None] * bv[:, None, :]
        cols = iu[:, :, None] * self.basis_v.size + iv[:, None, :]
        rows = np.broadcast_to(np.arange(u.size)[:, None, None], values.shape)
        return sp.csr_matrix((values.ravel(), (rows.ravel(), cols.ravel())),
                             shape=(u.size, self.basis_u.size * self.basis_v.size))

    def derivative(self, u: ArrayLike, v: ArrayLike, du: int = 0, dv: int = 0,
                   control_points: ArrayLike | None = None) -> NDArray[np.float64]:
        """Partial derivative ``∂^{du+dv} x / ∂u^du ∂v^dv`` at parameters ``(u, v)``.

        ``u`` and ``v`` broadcast to a common shape ``S``; returns ``S + (3,)``.
        ``control_points`` evaluates another net (e.g. a displacement) on the same bases.

        The surface's own net is evaluated from its Bézier patches (:mod:`splinedeform.patches`,
        computed once it has been asked for as many points as it has cells); until then, and
        for another net, by the sum over the ``(n+1)²`` control points of each parameter's
        cell, ``Σ_r Σ_s D^du b_r(u) D^dv b_s(v) p_rs``. With :attr:`net_weights`, in
        homogeneous coordinates and the quotient rule (:mod:`splinedeform.rational`).
        """
        if self.net_weights is not None:
            return rational.derivative(self, u, v, du, dv, control_points)
        Q = None
        own = control_points is None and _order(du) and _order(dv)
        one = type(u) in _SCALARS and type(v) in _SCALARS
        if own:
            Q = patches_when_worth(self, du, dv, 1 if one else np.broadcast(u, v).size)
        degrees = (self.basis_u.degree - du, self.basis_v.degree - dv)
        if own and one:
            if Q is not None:
                return evaluate_patch_point(Q, degrees, self.basis_u, self.basis_v, u, v)
            if _has_span_form(self.basis_u) and _has_span_form(self.basis_v) and min(degrees) >= 0:
                return self._direct_point(u, v, du, dv)
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        if Q is not None:
            points = evaluate_patches(Q, degrees, self.basis_u, self.basis_v, u.ravel(),
                                      v.ravel())
            return points.reshape(u.shape + (3,))
        P = self.control_points if control_points is None else np.asarray(control_points, float)
        uf, vf = u.ravel(), v.ravel()
        n_v = P.shape[1]
        flat = P.reshape(P.shape[0] * n_v, -1)
        out = np.empty((uf.size, flat.shape[1]))
        for start in range(0, uf.size, BLOCK):
            block = slice(start, start + BLOCK)
            iu, bu = self.basis_u.nonzero(uf[block], du)
            iv, bv = self.basis_v.nonzero(vf[block], dv)
            # the (n+1)² control points of each parameter's cell: Σ_r Σ_s bu_r bv_s p_rs
            count = iu.shape[0]
            index = (iu[:, :, None] * n_v + iv[:, None, :]).reshape(count, -1)
            weights = (bu[:, :, None] * bv[:, None, :]).reshape(count, -1)
            np.einsum("pk,pkc->pc", weights, flat[index], out=out[block])
        return out.reshape(u.shape + P.shape[2:])

    def _direct_point(self, u: float, v: float, du: int, dv: int) -> NDArray[np.float64]:
        """One point by the ``(n+1)²`` control points of its cell, from plain floats."""
        i, s = self.basis_u.locate_scalar(u)
        j, t = self.basis_v.locate_scalar(v)
        bu = span_values(self.basis_u, i, s, du)
        bv = span_values(self.basis_v, j, t, dv)
        net = self.control_points[np.ix_(span_indices(self.basis_u, i),
                                         span_indices(self.basis_v, j))]   # (n+1, n+1, 3)
        return bu @ (bv @ net)

    def evaluate(self, u: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """Points ``x(u, v)``; ``u`` and ``v`` broadcast to ``S``, result ``S + (3,)``."""
        if type(u) in _SCALARS and type(v) in _SCALARS:   # one point: no array set-up at all
            Q = self._cache.get(_POINTS)
            if Q is not None:
                return evaluate_patch_point(Q, (self.basis_u.degree, self.basis_v.degree),
                                            self.basis_u, self.basis_v, u, v)
        return self.derivative(u, v)

    def evaluate_grid(self, u: ArrayLike, v: ArrayLike, du: int = 0, dv: int = 0,
                      control_points: ArrayLike | None = None) -> NDArray[np.float64]:
        """Tensor grid evaluation ``X[i, j] = Σ_kl p_kl D^du b_k(u_i) D^dv b_l(v_j)``.

        Two sparse products ``X_c = B_u P_c B_vᵀ`` for all coordinates ``c`` at once, with
        the collocation matrices ``B_u``, ``B_v`` of the two bases (one evaluation where
        both directions share a basis and an order); result ``(len(u), len(v), c)``.
        With :attr:`net_weights`, the same on the homogeneous net and the quotient rule.
        """
        if self.net_weights is not None:
            return rational.evaluate_grid(self, u, v, du, dv, control_points)
        P = self.control_points if control_points is None else np.asarray(control_points, float)
        u = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        v = np.atleast_1d(np.asarray(v, dtype=float)).ravel()
        if du == dv and self.basis_u is self.basis_v:     # one evaluation for both
            index, values = self.basis_u.nonzero(np.concatenate([u, v]), du)
            Bu = index[:u.size], values[:u.size]
            Bv = index[u.size:], values[u.size:]
        else:
            Bu, Bv = self.basis_u.nonzero(u, du), self.basis_v.nonzero(v, dv)
        n_u, n_v = P.shape[:2]
        along_u = collocate(*Bu, P.reshape(n_u, -1))            # (N_u, n_v · c), C order
        width = along_u.shape[1] // n_v
        # (N_u, n_v, c) -> (n_v, N_u, c): the rows moved as records of c numbers, which
        # numpy copies faster than the strided three-number blocks of a float transpose
        record = np.dtype((np.void, width * along_u.itemsize))
        rows = np.ascontiguousarray(along_u.view(record).reshape(u.size, n_v).T)
        out = collocate(*Bv, rows.view(np.float64).reshape(n_v, -1))   # (N_v, N_u · c)
        return out.reshape(v.size, u.size, width).transpose(1, 0, 2)

    def normal(self, u: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """Unit normal ``n = x_u × x_v / |x_u × x_v|``; raises where the surface is degenerate."""
        cross = np.cross(self.derivative(u, v, 1, 0), self.derivative(u, v, 0, 1))
        length = np.linalg.norm(cross, axis=-1, keepdims=True)
        if np.any(length <= 1e-14 * max(1.0, float(np.abs(self.control_points).max()))):
            raise InputError("the surface is degenerate (x_u × x_v = 0) at some of the given "
                             "parameters; its normal is undefined there")
        return cross / length

    def sample_parameters(self, resolution: int | tuple[int, int]
                          ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Evenly spaced parameters covering the domain (periodic directions include the seam twice)."""
        ru, rv = (resolution, resolution) if np.isscalar(resolution) else resolution
        if int(ru) < 2 or int(rv) < 2:
            raise InputError(f"tessellation resolution must be >= 2 per direction, got {resolution}")
        if int(ru) * int(rv) > MAX_SAMPLES:
            raise InputError(
                f"tessellation resolution {resolution} asks for {int(ru) * int(rv):.3g} "
                f"vertices (about {int(ru) * int(rv) * 72 / 2**30:.3g} GiB with the faces); "
                f"at most {MAX_SAMPLES} (e.g. 2048 x 2048)")
        return (np.linspace(0.0, self.basis_u.length, int(ru)),
                np.linspace(0.0, self.basis_v.length, int(rv)))

    def tessellate(self, resolution: int | tuple[int, int] = 32,
                   control_points: ArrayLike | None = None
                   ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
        """Triangle mesh of the surface on a ``ru × rv`` parameter grid.

        Returns ``vertices (ru*rv, 3)`` and ``faces (2 (ru-1)(rv-1), 3)`` (counter-clockwise
        in parameter space, so face normals follow ``x_u × x_v``).
        """
        u, v = self.sample_parameters(resolution)
        vertices = self.evaluate_grid(u, v, control_points=control_points).reshape(-1, 3)
        return vertices, grid_faces(u.size, v.size)


def knots_summary(basis: Basis) -> str:
    """A basis's knots in a few words: ``'open' 4 cells``, ``knot vector of 11``, or
    ``rational`` before either."""
    if isinstance(basis, RationalBasis):
        return f"rational {knots_summary(basis.basis)}"
    if isinstance(basis, KnotVectorBasis):
        return f"knot vector of {np.size(basis.knots)}"
    return f"{basis.kind!r} {basis.cells} cells"


def grid_faces(ru: int, rv: int) -> NDArray[np.int64]:
    """Two triangles per quad of a row-major ``ru × rv`` vertex grid."""
    i, j = np.meshgrid(np.arange(ru - 1), np.arange(rv - 1), indexing="ij")
    a = (i * rv + j).ravel()
    b, c, d = a + rv, a + rv + 1, a + 1
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)
