"""Checks of a model's options and its static solve ``K_r d = F_r``.

The stiffness is factorised once (a band Cholesky, :func:`splinedeform.solvers.factor.
factorise`) and kept on the model for further loads. A singular ``K_r`` is reported with
what the weights and constraints leave without energy; an ill-conditioned one is accepted
when one step of iterative refinement estimates the relative error below
:data:`STATIC_TRUST`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .errors import InputError, SingularSystemError
from .material import Material
from .physics import PHYSICS
from .solvers.factor import factorise

if TYPE_CHECKING:  # pragma: no cover
    from .model import Model

Array = NDArray[np.float64]
STATIC_TRUST = 1e-6
"""Largest estimated relative error accepted from an ill-conditioned static solve."""


def check_options(material: Material, mass_matrix: str, rest: str, physics: str) -> None:
    """Refuse a material that is not one, and unknown mass, rest or physics options."""
    if not isinstance(material, Material):
        raise InputError(f"material must be a splinedeform.Material, got "
                         f"{type(material).__name__}")
    if mass_matrix not in ("consistent", "lumped"):
        raise InputError(f"mass_matrix must be 'consistent' or 'lumped', got {mass_matrix!r}")
    if rest not in ("initial", "none"):
        raise InputError(f"rest must be 'initial' or 'none', got {rest!r}")
    if physics == "shell":
        raise InputError("physics 'shell' couples x, y and z and has its own material: use "
                         "splinedeform.ShellModel(surface, ShellMaterial(E, nu, thickness, "
                         "density), boundary)")
    if physics not in PHYSICS:
        raise InputError(f"physics must be one of {PHYSICS}, got {physics!r}")


def solve_stiffness(model: "Model", F: Array) -> Array:
    """``d = K_r⁻¹ F`` for the reduced stiffness of ``model`` (``F`` of shape
    ``(n_free, c)``), with the refusals and the refinement step described above."""
    m = model.material
    weights = [m.w10, m.w01, m.w20, m.w11, m.w02]
    message = ("the stiffness matrix is singular for these boundary conditions and weights "
               f"(edges {model.constraints.edges}, weights w10..w02 = "
               f"{weights}): "
               "some deformation has no energy. Constrain the edges the weights do not "
               "reach (e.g. tension only in u needs pinned u0/u1 edges), or add weights")
    if model.rigid_modes:
        raise SingularSystemError(message + f" ({model.rigid_modes} deformation(s) without "
                                  "energy, counted from the weights and the constraints)")
    try:
        lu = getattr(model, "_stiffness_factor", None)
        if lu is None:                     # once constrained K is SPD: a Cholesky,
            lu = model._stiffness_factor = factorise(model._K)   # kept for further loads
        d = lu.solve(F)
    except RuntimeError:
        raise SingularSystemError(message) from None
    scale = max(np.linalg.norm(F), 1e-300)
    residual = np.linalg.norm(model._K @ d - F) / scale
    if np.all(np.isfinite(d)) and residual <= 1e-8:
        return d
    if model.rigid_modes is None or not np.all(np.isfinite(d)):
        raise SingularSystemError(message)
    # non-singular by structure, but ill-conditioned: one refinement step estimates
    # the error of d (the correction's size), accepted up to STATIC_TRUST
    correction = lu.solve(F - model._K @ d)
    error = float(np.abs(correction).max() / max(np.abs(d).max(), 1e-300))
    if np.isfinite(error) and error <= STATIC_TRUST:
        return d + correction
    raise SingularSystemError(
        f"the stiffness matrix is not singular but too ill-conditioned to solve: relative "
        f"residual {residual:.1g}, estimated relative error {error:.1g} (one refinement "
        f"step) for weights w10..w02 = {weights}. "
        "Raise the smallest weight, or use fewer cells or a lower degree")
