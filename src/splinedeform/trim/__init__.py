"""Trimmed faces: trim loops, cut cells, their quadrature and Höllig's WEB-spline basis."""

from .cells import CUT, INSIDE, OUTSIDE, Grid, classify_cells
from .loops import CircleLoop, PolygonLoop, TrimDomain
from .piecewise_loop import PiecewiseLoop
from .quadrature import TrimQuadrature, trim_quadrature
from .spline_loop import SplineLoop

__all__ = ["CUT", "INSIDE", "OUTSIDE", "CircleLoop", "Grid", "PiecewiseLoop", "PolygonLoop", "SplineLoop", "TrimDomain",
           "TrimQuadrature", "classify_cells", "trim_quadrature"]
