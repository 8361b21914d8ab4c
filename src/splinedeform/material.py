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
