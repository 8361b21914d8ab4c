"""Material of the thin plate under tension (Terzopoulos' controlled-continuity energy).

``E(d) = ½ ∫∫ w10|d_u|² + w01|d_v|² + w20|d_uu|² + 2 w11|d_uv|² + w02|d_vv|² du dv``,
mass density ``μ`` (``mass``), viscous damping ``γ`` (``damping``) and optional stiffness-
proportional (Rayleigh) damping ``β`` (``rayleigh``), so that ``C = (γ/μ) M + β K``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from .errors import InputError

WEIGHTS = ("w10", "w01", "w20", "w11", "w02")


@dataclass(frozen=True)
class Material:
    """Mass, damping and the five stiffness weights of the energy.

    Parameters
    ----------
    mass : float
        Mass per unit parameter area ``μ > 0``.
    damping : float
        Viscous damping ``γ >= 0`` (force per unit velocity and area).
    rayleigh : float
        Stiffness-proportional damping ``β >= 0``; modal damping is ``c_i = γ/μ + β λ_i``.
    w10, w01 : float
        Tension (membrane) weights in u and v, ``>= 0``.
    w20, w11, w02 : float
        Bending (thin plate) weights, ``>= 0``; ``w20 = w11 = w02 = D`` is a Kirchhoff plate
        of flexural rigidity ``D`` (Poisson-independent for clamped/simply supported edges).

    Examples
    --------
    >>> Material(w10=1.0, w01=1.0).is_membrane
    True
    """

    mass: float = 1.0
    damping: float = 0.0
    rayleigh: float = 0.0
    w10: float = 0.0
    w01: float = 0.0
    w20: float = 0.0
    w11: float = 0.0
    w02: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, (bool, np.bool_, str, bytes)):
                raise InputError(f"material.{f.name} must be a real number, got {value!r}")
            if not isinstance(value, (int, float)):
                try:
                    value = float(value)
                except (TypeError, ValueError):
                    raise InputError(f"material.{f.name} must be a number, got {value!r}") from None
            if not math.isfinite(value):
                raise InputError(f"material.{f.name} must be finite, got {value!r}")
            if value < 0:
                raise InputError(f"material.{f.name} must be >= 0, got {value!r}")
            object.__setattr__(self, f.name, float(value))
        if self.mass <= 0:
            raise InputError(f"material.mass must be > 0, got {self.mass!r}")
        if all(getattr(self, w) == 0 for w in WEIGHTS):
            raise InputError("all stiffness weights (w10, w01, w20, w11, w02) are zero: "
                             "the surface would have no elastic energy; set a tension "
                             "(w10, w01) or a bending (w20, w11, w02) weight > 0")

    @property
    def is_membrane(self) -> bool:
        """Tension only (no bending weights)."""
        return self.w20 == self.w11 == self.w02 == 0

    @property
    def bending(self) -> bool:
        """Any second-derivative weight present (needs degree >= 2)."""
        return (self.w20, self.w02) != (0.0, 0.0)

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


#: entries of the assembled matrices, and their ratio (the scale of ``λ = ω²``), must stay
#: below this (and the mass entries above its inverse), so that the eigensolver's products
#: and the modal exponentials keep inside the range of doubles (about 1e±308)
MATRIX_RANGE = 1e280


def check_scales(material: Material, K_max: float, M_max: float) -> None:
    """Refuse weights and mass whose assembled matrices doubles cannot carry.

    ``K_max = max |K_ij|`` and ``M_max = max |M_ij|`` of the reduced stiffness and mass
    matrices. Required: both finite, ``K_max <= R``, ``M_max >= 1/R`` and
    ``K_max / M_max <= R`` (an upper bound of scale of ``λ_max``) with
    ``R = MATRIX_RANGE``. The error is an :class:`InputError` whose ``key`` attribute is
    the material key to change (``material.mass`` or the largest weight).
    """
    weights = {w: getattr(material, w) for w in WEIGHTS if getattr(material, w)}
    largest = max(weights, key=lambda w: weights[w])
    problem = None
    if not (np.isfinite(K_max) and K_max <= MATRIX_RANGE):
        key, problem = largest, "the stiffness matrix overflows"
    elif not (np.isfinite(M_max) and M_max >= 1 / MATRIX_RANGE):
        key, problem = "mass", "the mass matrix underflows"
    elif K_max / M_max > MATRIX_RANGE:
        heavy = abs(math.log10(weights[largest])) >= abs(math.log10(material.mass))
        key, problem = (largest if heavy else "mass"), "the eigenvalues λ = ω² overflow"
    if problem is None:
        return
    error = InputError(
        f"material.{key} = {getattr(material, key):g}: {problem} (largest stiffness entry "
        f"{K_max:.3g}, largest mass entry {M_max:.3g}; the solvers need them within "
        f"1e±{math.log10(MATRIX_RANGE):.0f} and their ratio below {MATRIX_RANGE:.0e}). "
        f"Rescale the units: e.g. divide every weight and load by the same factor")
    error.key = f"material.{key}"  # type: ignore[attr-defined]
    raise error
