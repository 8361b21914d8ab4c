"""Loads on one patch of a body.

A body's load vector is the patches' vectors, patch after patch; a load acts on every patch
unless it is wrapped in :class:`OnPatch`. A point load names parameters ``(u, v)`` of one
patch, so on a body it must be (``OnPatch(Point(u, v, force), patch=i)``).

A pressure pushes along ``s x_u × x_v`` on each patch, ``s`` the body's
:attr:`~splinedeform.body.Body.orientation` of that patch (:func:`along_normal`): on a
closed Brep the outward normal of every face, also where a face is marked reversed. A
single surface's pressure pushes along its own :attr:`~splinedeform.Surface.orientation`
(:func:`surface_field`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..loads import Load, Pressure, Profile
from ..surface import Surface


@dataclass(frozen=True)
class OnPatch(Load):
    """``load`` on patch ``patch`` of a body only (zero on the other patches).

    Examples
    --------
    >>> import splinedeform as sd
    >>> push = OnPatch(sd.Point(0.25, 0.5, (0, 0, -1.0)), patch=1)
    >>> push.patch, push.profile
    (1, Constant())
    """

    load: Load
    patch: int

    def __post_init__(self) -> None:
        if not isinstance(self.load, Load):
            raise InputError(f"OnPatch needs a load, got {type(self.load).__name__}")
        if isinstance(self.patch, bool) or not isinstance(self.patch, (int, np.integer)) \
                or self.patch < 0:
            raise InputError(f"OnPatch.patch must be a patch index >= 0, got {self.patch!r}")

    @property
    def profile(self) -> Profile:  # type: ignore[override]
        """The wrapped load's time profile."""
        return self.load.profile

    @property
    def time_dependent_field(self) -> bool:  # type: ignore[override]
        return self.load.time_dependent_field

    def terms(self) -> list[Load]:
        """One :class:`OnPatch` per term of the wrapped load."""
        parts = self.load.terms()
        return [self] if parts == [self.load] else [OnPatch(t, self.patch) for t in parts]

    def field_vector(self, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
        """The wrapped load's vector on ``surface`` (the patch it acts on)."""
        return self.load.field_vector(surface, t)


def surface_field(term: Load, surface: Surface, t: float = 0.0) -> NDArray[np.float64]:
    """One load term's vector on a single surface, a pressure along
    ``surface.orientation · x_u × x_v`` (the outward normal of a CAD face its Brep marks
    reversed, as on a body's patch)."""
    part = term.field_vector(surface, t)
    return -part if along_normal(term) and getattr(surface, "orientation", 1) < 0 else part


def along_normal(term: Load) -> bool:
    """Whether a load term pushes along its patch's normal ``x_u × x_v`` (a pressure,
    on every patch or on one), so that a patch the body turns over takes it with the
    opposite sign."""
    return isinstance(term.load if isinstance(term, OnPatch) else term, Pressure)
