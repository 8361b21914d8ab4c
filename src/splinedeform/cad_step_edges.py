"""The edges of a STEP or IGES file and the faces around them (run in the reader child).

:func:`list_step_body` reads the file once (:func:`splinedeform.cad_step_read.read_faces`)
and returns what :func:`splinedeform.cad_step_read.list_step_arrays` returns with the
file's edges: for each edge that is not degenerate (a pole), the numbers of the faces
that use it, from OpenCASCADE's ``TopExp.MapShapesAndAncestors(shape, EDGE, FACE)`` (a
seam, ``BRep_Tool.IsClosed(edge, face)``, has its face twice), and points sampled inside
it in the file's unit. :mod:`splinedeform.cad_topology` places them on the faces' sides.
This module imports only numpy, OCP and the reader, so the child starts quickly.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .cad_step_read import faces_listing, ocp, read_faces
from .cad_units import millimetres

#: interior points sampled along every edge for the topology (as for .3dm files)
EDGE_SAMPLES = 9


def list_step_body(path: Path) -> dict[str, Any]:
    """:func:`~splinedeform.cad_step_read.list_step_arrays` and the file's edges, read
    once: ``edges`` is one entry per non-degenerate edge, ``{"faces": [face number per
    use], "points": (EDGE_SAMPLES, 3) interior points in the file's unit}`` (see the
    module docstring; run in the child)."""
    ocp()
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS

    try:
        from OCP.OCP.collections import (
            IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher as EdgeMap,
            IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as FaceMap)
    except ImportError:  # pragma: no cover - older OCP
        from OCP.TopTools import (TopTools_IndexedDataMapOfShapeListOfShape as EdgeMap,
                                  TopTools_IndexedMapOfShape as FaceMap)
    cast = TopoDS.Edge if hasattr(TopoDS, "Edge") else TopoDS.Edge_s
    reader, faces, units = read_faces(path)
    data = faces_listing(path, reader, faces, units)
    numbers = FaceMap()
    for face in faces:
        numbers.Add(face)
    ancestors = EdgeMap()
    TopExp.MapShapesAndAncestors_s(reader.OneShape(), TopAbs_EDGE, TopAbs_FACE, ancestors)
    scale = millimetres(units)
    t = (np.arange(EDGE_SAMPLES) + 0.5) / EDGE_SAMPLES
    edges = []
    for k in range(1, ancestors.Extent() + 1):
        edge = cast(ancestors.FindKey(k))
        if BRep_Tool.Degenerated_s(edge):
            continue
        owners: list[int] = []
        for face in ancestors.FindFromIndex(k):       # a seam's face may be listed twice
            number = numbers.FindIndex(face) - 1
            if number >= 0 and number not in owners:
                owners += [number] * (2 if BRep_Tool.IsClosed_s(edge, faces[number]) else 1)
        curve = BRepAdaptor_Curve(edge)
        a, b = curve.FirstParameter(), curve.LastParameter()
        points = [curve.Value(a + (b - a) * s) for s in t]
        edges.append({"faces": owners,
                      "points": np.array([(p.X(), p.Y(), p.Z()) for p in points]) / scale})
    data["edges"] = edges
    return data
