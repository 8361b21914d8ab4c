"""splinedeform: physical deformation of B-spline surfaces, solved analytically.

>>> import splinedeform as sd
>>> surf = sd.shapes.plane(size=(1.0, 1.0), cells=(8, 8))
>>> model = sd.Model(surf, sd.Material(w20=1, w11=1, w02=1), boundary="clamped")
>>> st = model.static(sd.loads.Uniform((0, 0, -1.0)))
"""

from . import loads
from .basis import BSplineBasis
from .body import Body, BodyModel, find_interfaces
from .knots import KnotVectorBasis, RationalBasis
from .errors import InputError, ScenarioError, SingularSystemError
from .loads import Constant, Function, Harmonic, Piecewise, Point, Pressure, Step, Uniform
from .material import Material
from .model import Model
from .physics.shell import ShellMaterial
from .physics.shell_model import AreaForce, ShellModel
from .solution import Energy, Solution, StaticSolution
from .surface import Surface

try:  # built-in shapes and fitting
    from . import shapes
except ImportError:  # pragma: no cover - during development only
    shapes = None  # type: ignore[assignment]

__version__ = "0.1.0"


def __getattr__(name: str) -> object:
    """``splinedeform.sweep``: imported on first use (it needs pydantic; Dask to run)."""
    if name == "sweep":
        from .study import sweep

        return sweep
    raise AttributeError(f"module 'splinedeform' has no attribute {name!r}")

__all__ = ["AreaForce", "Body", "BodyModel", "find_interfaces", "ShellMaterial", "ShellModel", "BSplineBasis", "KnotVectorBasis", "RationalBasis", "Constant", "Energy", "Function", "Harmonic", "InputError",
           "Material", "Model", "Piecewise", "Point", "Pressure", "ScenarioError",
           "SingularSystemError", "Solution", "StaticSolution", "Step", "Surface", "Uniform", "sweep",
           "loads", "shapes", "__version__"]
