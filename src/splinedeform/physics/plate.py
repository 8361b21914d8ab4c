"""The thin plate under tension as a :class:`~.formulation.Formulation`.

One unknown per control point, shared by x, y and z (DESIGN.md §1.5): the free state is
``(n_free, 3)`` and every coordinate has the same ``K_r``, ``M_r`` and

.. math:: C_r = (γ/μ) M_r + β K_r.

The energy is measured in the parameters (``parametric``, Kronecker Gram matrices,
:mod:`splinedeform.assembly`) or on the initial surface (``intrinsic``, :mod:`.intrinsic`);
which one, and the constraint map of a surface or a body, are decided by the model's
constructors (:class:`splinedeform.Model`, :class:`splinedeform.BodyModel`). Rigid modes
are counted from the weights and the constraints (:mod:`splinedeform.spectrum`), so
:attr:`rigid_basis` is ``None``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import SingularSystemError
from ..material import Material
from ..readout import BodyReadout, Readout
from ..solvers.system import Reduction
from ..static_solve import solve_stiffness

Array = NDArray[np.float64]
METHODS = ("analytic", "newmark", "radau3", "radau5", "radau7", "genalpha", "rk45", "dop853",
           "radau", "bdf")


@dataclass
class PlateFormulation:
    """The plate of one surface (``surface``) or of a body's patches (``patches``).

    ``reduction_type`` makes the load vectors (a body's
    :class:`~splinedeform.body.model.BodyReduction` reads its patches one after another).
    """

    physics: str
    material: Material
    surface: Any = None
    patches: tuple | None = None
    reduction_type: type = Reduction
    unconstrained: bool = False
    edges: Any = None

    per_point = 1
    unknowns_label = "free control points"
    methods = METHODS
    rigid_basis = None

    @property
    def damping_rate(self) -> float:
        """``γ/μ``."""
        return self.material.damping / self.material.mass

    @property
    def rayleigh(self) -> float:
        """``β``."""
        return self.material.rayleigh

    def reduction(self, T: sp.spmatrix, rest: Array | None) -> Reduction:
        return self.reduction_type(T, self.surface if self.patches is None else self.patches,
                                   rest)

    def static_displacement(self, model: Any, F: Array) -> Array:
        """The band Cholesky of :func:`splinedeform.static_solve.solve_stiffness`, after
        refusing a surface that nothing holds (its translations cost no energy)."""
        if self.unconstrained:
            raise SingularSystemError(
                "static solve of an unconstrained surface: every edge is free and no control "
                "point is fixed, so rigid translations cost no energy and K is singular. "
                "Fix an edge (boundary='clamped' or e.g. {'u0': 'pinned'}) or some control "
                "points (fixed=mask)")
        return solve_stiffness(model, F)

    def eigen_options(self, K_r: sp.spmatrix, check_spectrum: bool) -> dict[str, Any]:
        """The condition-number guard (:func:`~splinedeform.solvers.rigid.check_resolved`),
        or none; the advice is the model's (:func:`splinedeform.spectrum.eigen_advice`)."""
        return {"guard": "condition" if check_spectrum else "off"}

    def readout(self, T: sp.spmatrix, M_r: sp.spmatrix, K_r: sp.spmatrix) -> Any:
        if self.patches is None:
            return Readout(self.surface, T, M_r, K_r)
        return BodyReadout(self.patches, T, M_r, K_r)
