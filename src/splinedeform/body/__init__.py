"""Bodies: several B-spline patches deformed as one connected surface.

A body is a list of patches and the interfaces between their edges (shared edges between two
patches, seams where a patch meets itself, C0 knot lines inside a patch). Interfaces are found
geometrically (:mod:`.topology`), the body (:mod:`.body`) holds the patches, and
:class:`BodyModel` (:mod:`.model`) deforms them as one model, the control points of
conforming interfaces merged (:mod:`.constraints`).
"""

from .body import Body
from .interface import EDGES, Interface
from .loads import OnPatch
from .model import BodyModel
from .topology import Topology, find_interfaces, find_topology

__all__ = ["Body", "BodyModel", "EDGES", "Interface", "OnPatch", "Topology",
           "find_interfaces", "find_topology"]
