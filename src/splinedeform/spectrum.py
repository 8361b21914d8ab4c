"""A model's modes: what the eigensolvers are given, which one runs, and the cache.

The solvers (:mod:`splinedeform.solvers.modal_basis`) take matrices or their Kronecker
factors; this module gathers them from a :class:`~splinedeform.Model` and dispatches:

* :func:`kronecker_factors` — the reduced 1-D Gram matrices
  (:class:`~splinedeform.solvers.system.KroneckerFactors`) when ``K_r`` and ``M_r`` are sums
  of Kronecker products (parametric physics, consistent mass, per-edge constraints
  ``T = T_u ⊗ T_v``); :func:`kronecker_reason` says why not otherwise, and
  :func:`separable_reason` why the separable factors (``w11 = 0`` as well) do not apply;
* :func:`rigid_count` — the dimension of ``null K_r`` from the weights and the constraints
  (:func:`splinedeform.solvers.rigid.rigid_count`);
* :func:`modal_basis` and :func:`eigen` — the strategy of
  :func:`~splinedeform.solvers.modal_basis.choose`, cached on the model.
"""

from __future__ import annotations

import time
import weakref
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .errors import InputError
from .solvers import kronecker_product, modal_basis, rigid
from .solvers.kronecker_product import KroneckerProduct
from .solvers.rigid import UnresolvedSpectrum
from .solvers.system import KroneckerFactors

if TYPE_CHECKING:
    from .model import Model

Array = NDArray[np.float64]


_MASS: weakref.WeakKeyDictionary[Any, Any] = weakref.WeakKeyDictionary()
NO_FACTORS = ("a body of several patches, or a patch whose C0 lines are coupled, has no "
              "Kronecker factors")


def kronecker_reason(model: Any) -> str | None:
    """Why the Kronecker factors do not apply to ``model`` (``None`` if they do)."""
    if getattr(getattr(model, "surface", None), "net_weights", None) is not None:
        return "the NURBS weights are not a product a_k b_l (no Kronecker factors)"
    if getattr(model, "gram_u", True) is None:
        return NO_FACTORS
    if getattr(model, "physics", "parametric") != "parametric":
        return "the surface metric varies over the parameters (no Kronecker factors)"
    if model.mass_matrix != "consistent":
        return "the lumped mass is not a Kronecker product of the Gram factors"
    if model.constraints.T_u is None or model.constraints.T_v is None:
        return "the fixed control points do not leave a rectangular free region"
    return None


def separable_reason(model: Any) -> str | None:
    """Why the separable fast path does not apply to ``model`` (``None`` if it does)."""
    if getattr(getattr(model, "surface", None), "net_weights", None) is not None:
        return "the NURBS weights are not a product a_k b_l (no Kronecker factors)"
    if getattr(model, "gram_u", True) is None:
        return NO_FACTORS
    if getattr(model, "physics", "parametric") != "parametric":
        return "the surface metric varies over the parameters (no Kronecker factors)"
    if model.material.w11 != 0:
        return "the twist weight w11 is not 0 (its term G1u⊗G1v couples the directions)"
    if model.mass_matrix != "consistent":
        return "the lumped mass does not share the Gram factors G0 of the stiffness"
    if model.constraints.T_u is None or model.constraints.T_v is None:
        return "the fixed control points do not leave a rectangular free region"
    return None


def kronecker_factors(model: Model) -> KroneckerFactors:
    """The reduced 1-D Gram matrices ``Ĝ_a = Tᵀ G_a T`` of a Kronecker-structured model."""
    reason = kronecker_reason(model)
    if reason is not None:
        raise InputError(f"no Kronecker factors: {reason}")
    m, c = model.material, model.constraints

    def reduce(T: Any, G: Any) -> Array:
        return np.asarray((T.T @ G @ T).toarray())

    orders_u = [a for w, a in ((m.w10, 1), (m.w20, 2)) if w]
    orders_v = [a for w, a in ((m.w01, 1), (m.w02, 2)) if w]
    shared = model._factors          # the same reductions, made with the model's matrices
    return KroneckerFactors(
        tuple(G.toarray() for G in shared.u) if shared is not None else
        tuple(reduce(c.T_u, G) for G in model.gram_u),
        tuple(G.toarray() for G in shared.v) if shared is not None else
        tuple(reduce(c.T_v, G) for G in model.gram_v),
        (m.w10, m.w01, m.w20, m.w11, m.w02), m.mass,
        rigid.direction_rigid(model.surface.basis_u, c.T_u, orders_u),
        rigid.direction_rigid(model.surface.basis_v, c.T_v, orders_v))


def rigid_count(model: Model) -> int | None:
    """Dimension of ``null K_r`` (:func:`splinedeform.solvers.rigid.rigid_count`)."""
    if model.physics == "intrinsic":
        # T |∇_S d|²: zero on constants only. Without tension D (Δ_S d)² vanishes on
        # harmonic fields, which a clamped edge's zero value and slope make zero (unique
        # continuation, span to span); otherwise no structure is known
        if model.material.w10 == 0:
            clamped = model.material.w20 > 0 and "clamped" in model.constraints.edges.values()
            return 0 if clamped else None
        terms = [(1, 0), (0, 1)]
    else:
        terms = rigid.parametric_terms(model.material)
    return rigid.rigid_count(terms, model.surface.basis_u, model.surface.basis_v,
                             model.constraints)


def choose(model: Any, eigensolver: str = "auto", truncated: bool = False) -> str:
    """:func:`~splinedeform.solvers.modal_basis.choose` for a model."""
    return modal_basis.choose(model.n_free, eigensolver, truncated,
                              separable_reason(model) is None)


def eigen_advice(model: Model) -> str:
    """What to change when an eigen-solution cannot be trusted."""
    advice = modal_basis.DEFAULT_ADVICE
    if separable_reason(model) is None:
        advice += ", or eigensolver='separable', which resolves each direction apart"
    return advice


def eigen(model: Model, k: int | None, check_spectrum: bool = True) -> tuple[Array, Array]:
    """See :meth:`splinedeform.Model.eigen` (``k`` already checked)."""
    n = model.n_free
    strategy = choose(model, "auto", truncated=k is not None and k <= n // 2)
    few = k is not None and n >= 400 and k <= n // 10
    if (strategy == "dense" and few and not any(key[1:3] == (None, None) for key in model._bases)
            and separable_reason(model) is not None):
        strategy = "sparse"
    if strategy == "sparse":
        sparse = modal_basis_of(model, "sparse", k, None, check_spectrum)
        assert isinstance(sparse, modal_basis.DenseBasis)
        return sparse.lam, sparse.phi
    basis = modal_basis_of(model, "auto" if strategy == "dense" else strategy, None, None,
                           check_spectrum)
    if isinstance(basis, modal_basis.DenseBasis):
        return basis.lam[:k], basis.phi[:, :k]
    if k is None and n > modal_basis.DENSE_MAX:
        raise InputError(f"all {n} modes as an explicit matrix need "
                         f"{8 * n * n / 2**30:.1f} GiB; ask for the lowest k modes, or "
                         "use dynamic(), which keeps the Kronecker factors")
    order = np.argsort(basis.lam, kind="stable")[:k]
    return basis.lam[order], basis.columns(order)


def eigen_options(model: Model, check_spectrum: bool = True) -> dict[str, Any]:
    """The eigensolvers' ``guard``, ``advice`` (and ``order``) from the model's formulation
    (:meth:`~splinedeform.physics.formulation.Formulation.eigen_options`)."""
    options = model.formulation.eigen_options(model.matrices()[2], check_spectrum)
    options.setdefault("advice", eigen_advice(model))
    return options


def kronecker_mass(model: Model, M: Any) -> KroneckerProduct | None:
    """``M_r = μ Ĝ0u ⊗ Ĝ0v`` applied through its reduced 1-D factors
    (:mod:`~splinedeform.solvers.kronecker_product`) where the model has them (tensor-product
    constraints, a consistent mass) and they reproduce ``M_r``; else ``None``. Made once
    per model."""
    if model not in _MASS:
        factors = getattr(model, "_factors", None)
        _MASS[model] = None if factors is None or getattr(model, "mass_matrix", "") != \
            "consistent" else kronecker_product.checked(
                KroneckerProduct(factors.u[0], factors.v[0], model.material.mass), M)
    return _MASS[model]


def modal_basis_of(model: Model, eigensolver: str = "auto", modes: int | None = None,
                   omega_max: float | None = None, check_spectrum: bool = True
                   ) -> modal_basis.ModalBasis:
    """See :meth:`splinedeform.Model.modal_basis` (cached in ``model._bases``)."""
    truncated = modes is not None or omega_max is not None
    strategy = choose(model, eigensolver, truncated)
    key = (strategy, modes, omega_max) + (() if check_spectrum else (False,))
    if key in model._bases:
        return model._bases[key]
    start = time.perf_counter()
    M, _, K = model.matrices()
    options = eigen_options(model, check_spectrum)
    if strategy == "sparse":
        basis: modal_basis.ModalBasis = modal_basis.sparse_basis(
            K, M, modes, omega_max, model.rigid_modes, **options,
            mass_product=kronecker_mass(model, M))
    elif truncated:
        basis = modal_basis.truncate(modal_basis_of(model, eigensolver, None, None,
                                                    check_spectrum), modes, omega_max)
    else:
        try:
            basis = _complete_basis(model, strategy, options)
        except UnresolvedSpectrum:
            if eigensolver != "auto" or separable_reason(model) is not None:
                raise
            basis = _complete_basis(model, "separable", options)   # each direction apart
    model._bases[key] = basis
    model.timings["eigen"] = time.perf_counter() - start
    return basis


def _complete_basis(model: Model, strategy: str, options: dict[str, Any]
                    ) -> modal_basis.ModalBasis:
    if strategy == "separable":
        reason = separable_reason(model)
        if reason is not None:
            raise InputError(f"the separable eigensolver does not apply: {reason}; use "
                             "eigensolver='dense' or 'sparse'")
        return modal_basis.separable_basis(kronecker_factors(model))
    if kronecker_reason(model) is None:
        basis = modal_basis.kronecker_basis(kronecker_factors(model), model.rigid_modes,
                                            eigen_advice(model))
    else:
        M, _, K = model.matrices()
        basis = modal_basis.dense_basis(K, M, model.rigid_modes, options["advice"],
                                        options["guard"])
    model._eigen = (basis.lam, basis.phi)
    return basis
