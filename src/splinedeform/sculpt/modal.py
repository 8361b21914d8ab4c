"""Modal data for sculpting and the per-frame modal sum.

A push is a point force ``P`` at parameters ``(u, v)`` switched on at ``t_on`` and off at
``t_off`` (a step).  With mass-normalised modes ``Φ`` (``Φᵀ M Φ = I``) and modal damping
``c_i = γ/μ + β λ_i`` each mode obeys ``q_i'' + c_i q_i' + λ_i q_i = φ_i(u, v) P s(t)``; the
response from rest to a unit step at ``t = 0`` is, with roots ``r_± = -c/2 ± √(c²/4 - λ)``,

    g(τ) = (1 - (r_+ e^{r_- τ} - r_- e^{r_+ τ}) / (r_+ - r_-)) / λ        (τ >= 0)

(complex roots when under-damped).  A push contributes ``φ_i(u, v) P (g(t - t_on) -
g(t - t_off))`` and pushes superpose; the displacement of the sampled surface points is
``Φ_s q(t)`` with ``Φ_s = E T Φ`` the modes evaluated on the sample grid.  Nothing is
rebuilt for a push: only ``φ(u, v)``, one row of the evaluation of ``T Φ``, is needed.
The page evaluates the same formula in JavaScript from the arrays of :class:`SculptBasis`.

A model of several patches (a :class:`~splinedeform.body.BodyModel`) is sampled patch by
patch, each on its own ``r × r`` grid, the grids one after the other: with the full net
``T Φ`` split patch by patch (``T Φ = [Φ_1; …; Φ_P]``) the evaluation is block diagonal,

    Φ_s = diag(E_1, …, E_P) T Φ,

and a push names its patch, ``φ_i = E_p(u, v) Φ_p``. Control points merged across an
interface are one row of ``Φ``, so the faces' edges move together in every mode.

A trimmed patch keeps its grid and adds the points where the grid crosses its trim loops,
after every patch's grid (:mod:`.trimmed`): ``Φ_s`` gets their rows ``E_p(u_c, v_c) Φ_p``,
the page draws the clipped mesh, and a push outside the trims is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..model import Model
from ..surface import Surface
from .trimmed import TrimmedSamples, outside_words, trimmed_samples

Array = NDArray[np.float64]
MAX_PAGE_SAMPLES = 400 * 400
"""Most sample points of every patch together: the finest grid one surface may have."""


@dataclass(frozen=True)
class Push:
    """Point force ``force`` at ``(u, v)`` of patch ``patch`` acting for ``t_on <= t < t_off``."""

    u: float
    v: float
    force: tuple[float, float, float]
    t_on: float
    t_off: float = math.inf
    patch: int = 0


def model_patches(model: Model) -> tuple[Surface, ...]:
    """The surfaces of ``model``: a body's patches, or its one surface."""
    patches = getattr(model, "patches", None)
    return tuple(patches) if patches else (model.surface,)


@dataclass(frozen=True)
class SculptBasis:
    """Modes of a model sampled on its surfaces' grids, with their frequencies and damping.

    Attributes
    ----------
    lam : (k,) eigenvalues ``λ_i = ω_i²`` (all > 0: rigid motions must be held).
    damping : (k,) modal damping ``c_i = γ/μ + β λ_i``.
    phi_net : (N, k) the modes on the full control net ``T Φ``, patch after patch.
    samples : per patch the parameters ``(u, v)`` of its ``(ru, rv)`` sample grid.
    phi_samples : (P ru rv, k) modes at the sample points, ``Φ_s = diag(E_p) T Φ``,
        patch after patch, row-major within a patch.
    units : the unit of the coordinates (a CAD file's), or None.
    trimmed : the crossing points, triangles and inside mask of trimmed patches
        (:mod:`.trimmed`), None when no patch is trimmed; their samples follow the grids.
    """

    model: Model
    lam: Array
    damping: Array
    phi_net: Array
    samples: tuple[tuple[Array, Array], ...]
    phi_samples: Array
    units: str | None = None
    trimmed: TrimmedSamples | None = None

    @property
    def patches(self) -> tuple[Surface, ...]:
        return model_patches(self.model)

    @property
    def is_body(self) -> bool:
        """Whether the model has several patches."""
        return len(self.samples) > 1

    @property
    def grid(self) -> tuple[int, int]:
        """``(ru, rv)``: the sample grid of one patch (every patch has the same)."""
        u, v = self.samples[0]
        return int(u.size), int(v.size)

    @property
    def sample_count(self) -> int:
        """Sample points of every patch together (grids, then trim crossings)."""
        ru, rv = self.grid
        extra = 0 if self.trimmed is None else len(self.trimmed.uv)
        return len(self.samples) * ru * rv + extra

    @property
    def samples_u(self) -> Array:
        """The sample parameters in u of a single surface."""
        return self._single()[0]

    @property
    def samples_v(self) -> Array:
        """The sample parameters in v of a single surface."""
        return self._single()[1]

    def _single(self) -> tuple[Array, Array]:
        if self.is_body:
            raise ValueError("a body's samples are per patch: use samples[p] or sample_point")
        return self.samples[0]

    def sample_point(self, index: int) -> tuple[int, float, float]:
        """``(patch, u, v)`` of sample ``index`` (patch after patch, row-major, then the
        trim crossings)."""
        ru, rv = self.grid
        beyond = int(index) - len(self.samples) * ru * rv
        if beyond >= 0 and self.trimmed is not None:
            u_c, v_c = self.trimmed.uv[beyond]
            return int(self.trimmed.patch[beyond]), float(u_c), float(v_c)
        patch, rest = divmod(int(index), ru * rv)
        u, v = self.samples[patch]
        return patch, float(u[rest // rv]), float(v[rest % rv])

    def net_offsets(self) -> NDArray[np.int64]:
        """Rows of each patch in the full net: patch ``p`` is ``offsets[p]:offsets[p+1]``."""
        return np.concatenate([[0], np.cumsum([s.shape[0] * s.shape[1] for s in self.patches])])

    def split_net(self, rows: Array) -> list[Array]:
        """Full-net rows ``(N, 3)`` as one ``(n_u, n_v, 3)`` net per patch."""
        parts = np.split(np.asarray(rows), self.net_offsets()[1:-1], axis=0)
        return [part.reshape(s.shape + (3,)) for part, s in zip(parts, self.patches)]

    def rest_net(self) -> Array:
        """The rest control points of every patch as full-net rows ``(N, 3)``."""
        return np.concatenate([s.control_points.reshape(-1, 3) for s in self.patches])

    def sample_matrix(self) -> sp.csr_matrix:
        """``diag(E_1, …, E_P)`` (and the trim crossings' rows): the full net to the sample
        points, ``(sample_count, N)``."""
        return sample_evaluation(self.patches, self.samples, self.trimmed)

    def rest_samples(self) -> Array:
        """Rest positions of the sample points, ``(sample_count, 3)``."""
        return np.asarray(self.sample_matrix() @ self.rest_net())

    def participation(self, u: float, v: float, patch: int = 0) -> Array:
        """Mode shapes at the grabbed point ``φ_i(u, v)`` of ``patch``, shape ``(k,)``;
        :class:`~splinedeform.errors.InputError` outside a trimmed patch's trims."""
        from ..trim.surface_trim import region_contains

        offsets = self.net_offsets()
        surface = self.patches[patch]
        if surface.trim is not None and not region_contains(surface, np.array([[u, v]]))[0]:
            raise InputError(outside_words(surface, u, v))
        E = surface.evaluation_matrix(np.array([u]), np.array([v]))
        return np.asarray(E @ self.phi_net[offsets[patch]:offsets[patch + 1]]).ravel()

    def step_response(self, tau: Array) -> Array:
        """``g_i(τ)`` of every mode to a unit step at ``τ = 0``, shape ``tau.shape + (k,)``."""
        tau = np.asarray(tau, dtype=float)[..., None]
        half = self.damping / 2
        root = np.sqrt((half * half - self.lam).astype(complex))
        rp, rm = -half + root, -half - root
        t = np.maximum(tau, 0.0)
        g = (1 - (rp * np.exp(rm * t) - rm * np.exp(rp * t)) / (rp - rm)).real / self.lam
        return np.where(tau >= 0, g, 0.0)

    def modal(self, t: float, pushes: list[Push]) -> Array:
        """Modal coordinates ``q(t)``, shape ``(k, 3)``: the superposed push responses."""
        q = np.zeros((self.lam.size, 3))
        for push in pushes:
            weight = self.step_response(np.array(t - push.t_on))
            if math.isfinite(push.t_off):
                weight = weight - self.step_response(np.array(t - push.t_off))
            q += (self.participation(push.u, push.v, push.patch) * weight)[:, None] * np.asarray(push.force)[None, :]
        return q

    def displacement(self, t: float, pushes: list[Push]) -> Array:
        """Displacement of the sample points at ``t``, shape ``(ru*rv, 3)``: ``Φ_s q(t)``."""
        return self.phi_samples @ self.modal(t, pushes)


def sample_evaluation(patches: tuple[Surface, ...], samples: tuple[tuple[Array, Array], ...],
                      trimmed: TrimmedSamples | None = None) -> sp.csr_matrix:
    """``diag(E_1, …, E_P)`` with ``E_p`` patch ``p``'s evaluation on its grid ``samples[p]``,
    then (``trimmed``) a row ``E_p(u_c, v_c)`` per trim crossing in patch ``p``'s columns."""
    blocks = []
    for surface, (u, v) in zip(patches, samples):
        uu, vv = np.meshgrid(u, v, indexing="ij")
        blocks.append(surface.evaluation_matrix(uu.ravel(), vv.ravel()))
    E = sp.block_diag(blocks, format="csr") if len(blocks) > 1 else sp.csr_matrix(blocks[0])
    if trimmed is None or not len(trimmed.uv):
        return E
    rows = []
    for p, surface in enumerate(patches):
        at = trimmed.uv[trimmed.patch == p]
        rows.append(sp.csr_matrix(surface.evaluation_matrix(at[:, 0], at[:, 1]))
                    if len(at) else sp.csr_matrix((0, surface.shape[0] * surface.shape[1])))
    # the crossings follow each other patch by patch (:func:`.trimmed.trimmed_samples`)
    extra = sp.block_diag(rows, format="csr") if len(rows) > 1 else rows[0]
    return sp.vstack([E, extra], format="csr")


def sculpt_basis(model: Model, resolution: int = 32, modes: int | None = None,
                 units: str | None = None) -> SculptBasis:
    """Modes of ``model`` (all, or the lowest ``modes``) sampled on a ``resolution²`` grid
    of each of its patches (one for a single surface)."""
    patches = model_patches(model)
    if len(patches) * resolution**2 > MAX_PAGE_SAMPLES:
        finest = int(np.sqrt(MAX_PAGE_SAMPLES / len(patches)))
        raise InputError(f"{len(patches)} faces sampled {resolution}x{resolution} each are "
                         f"{len(patches) * resolution**2} sample points, more than the "
                         f"{MAX_PAGE_SAMPLES} the page draws; choose --resolution {finest} "
                         "or less")
    lam, phi = model.eigen(modes)
    if lam.size == 0:
        raise InputError("the model has no free control points to sculpt")
    if np.min(lam) <= 1e-12 * max(np.max(lam), 1e-300):
        raise InputError("the model has rigid-body modes (zero frequency); hold at least one "
                         "edge (pinned or clamped) so that a push has a rest position")
    mat = model.material
    damping = mat.damping / mat.mass + mat.rayleigh * lam
    phi_net = np.asarray(model.constraints.T @ phi)
    samples = tuple((np.asarray(u), np.asarray(v))
                    for u, v in (s.sample_parameters(resolution) for s in patches))
    trimmed = trimmed_samples(patches, samples)
    E = sample_evaluation(patches, samples, trimmed)
    return SculptBasis(model, lam, damping, phi_net, samples, np.asarray(E @ phi_net), units,
                       trimmed)
