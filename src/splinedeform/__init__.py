"""splinedeform: physical deformation of B-spline surfaces, solved analytically."""

from .basis import BSplineBasis
from .errors import InputError, ScenarioError, SingularSystemError
from .surface import Surface

__version__ = "0.1.0"

__all__ = ["BSplineBasis", "InputError", "ScenarioError", "SingularSystemError", "Surface",
           "__version__"]
