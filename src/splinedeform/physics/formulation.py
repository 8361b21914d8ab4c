"""The one interface every physics of a model implements.

A model is a body of patches with one energy. The thin plate under tension, measured in
the parameters or on the initial surface (:mod:`.plate`), and the Kirchhoff–Love shell
(:mod:`.shell_formulation`) give :class:`splinedeform.Model` the same few things, and the
model owns static, modes and dynamics once for all of them:

* the unknowns: ``per_point`` of them per control point in the rows of the constraint map
  ``d = T d_free``. The plate has one (x, y and z share ``T``; a free state is
  ``(n_free, 3)``); the shell three, interleaved (row ``3k + c``; a free state is
  ``(n_free,)``, one column ``(n_free, 1)`` for the solvers);
* ``K`` and ``M`` over all patches, patch after patch with their couplings, reduced
  ``K_r = Tᵀ K T``, ``M_r = Tᵀ M T``, and the damping

  .. math:: C_r = a M_r + β K_r, \\qquad a = γ/μ \\ (\\text{``damping_rate``}),
            \\ β \\ (\\text{``rayleigh``}),

  so that mode ``i`` has damping ``c_i = a + β λ_i`` (:func:`damping`);
* the load vectors ``F_r = Tᵀ F``: a :class:`~splinedeform.solvers.system.Reduction`
  whose ``field`` is a load term's force on the rows of ``T`` (:meth:`Formulation.reduction`);
* the rigid modes: an explicit basis of ``null K_r`` where the physics knows one (the
  shell's free rigid motions, :attr:`Formulation.rigid_basis`), else ``None`` and the
  model counts them from the weights and the constraints (:mod:`splinedeform.spectrum`);
* the static solve with its refusals (:meth:`Formulation.static_displacement`), the
  eigensolvers' guard and advice (:meth:`Formulation.eigen_options`), the time
  integrators it admits (:attr:`Formulation.methods`);
* the read-out of a free state as control nets, stresses where the physics has them
  (:meth:`Formulation.readout`).

Solvers take the matrices only; a formulation never imports the model.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..solvers.system import Reduction

Array = NDArray[np.float64]


@runtime_checkable
class Formulation(Protocol):
    """What a physics gives the model (see the module docstring).

    Attributes
    ----------
    physics : str
        ``"parametric"``, ``"intrinsic"`` or ``"shell"``.
    material : object
        The physics' material (:class:`~splinedeform.Material`,
        :class:`~splinedeform.ShellMaterial`).
    per_point : int
        Unknowns per control point in the rows of ``T``: 1 (x, y, z share ``T``) or 3
        (interleaved).
    unknowns_label : str
        How summaries name the free coordinates.
    methods : tuple of str
        The dynamic methods this physics admits.
    damping_rate, rayleigh : float
        ``a`` and ``β`` of ``C_r = a M_r + β K_r``.
    rigid_basis : ndarray ``(n_free, k)`` or None
        An explicit basis of ``null K_r`` where the physics knows one.
    """

    physics: str
    material: Any
    per_point: int
    unknowns_label: str
    methods: tuple[str, ...]
    damping_rate: float
    rayleigh: float
    rigid_basis: Array | None

    def reduction(self, T: sp.spmatrix, rest: Array | None) -> Reduction:
        """The map and the load fields on the rows of ``T`` (``rest``: ``−Tᵀ K p0`` or None)."""

    def static_displacement(self, model: Any, F: Array) -> Array:
        """``d`` with ``K_r d = F`` (the model's reduced matrices), refusing what has no
        equilibrium in this physics' words."""

    def eigen_options(self, K_r: sp.spmatrix, check_spectrum: bool) -> dict[str, Any]:
        """Keyword arguments of the eigensolvers for the reduced ``K_r``: ``guard``, and
        ``advice`` / ``order`` (of the unknowns, for the factor) where the physics has its
        own."""

    def readout(self, T: sp.spmatrix, M_r: sp.spmatrix, K_r: sp.spmatrix) -> Any:
        """The :class:`~splinedeform.readout.Readout` of a free state as control nets."""


def damping(formulation: Formulation, M_r: sp.spmatrix, K_r: sp.spmatrix) -> sp.csc_matrix:
    """``C_r = a M_r + β K_r`` with ``a = formulation.damping_rate``, ``β = formulation.rayleigh``."""
    return (formulation.damping_rate * M_r + formulation.rayleigh * K_r).tocsc()
