"""Bodies: several B-spline patches deformed as one connected surface.

A body is a list of patches and the interfaces between their edges (shared edges between two
patches, seams where a patch meets itself, C0 knot lines inside a patch).
"""

from .interface import EDGES, Interface

__all__ = ["EDGES", "Interface"]
