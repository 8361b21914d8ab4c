"""Interactive sculpting: a modal basis sent once, pushes superposed in closed form."""

from .export import payload
from .modal import Push, SculptBasis, sculpt_basis

__all__ = ["Push", "SculptBasis", "payload", "sculpt_basis"]
