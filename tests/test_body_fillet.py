"""A filleted box from OpenCASCADE deformed as one body: no seam opens, and the STEP file of
the deformed body, read back by OpenCASCADE, and its .3dm, read back by rhino3dm, are as
closed as its source.

The box ``2 × 3 × 1`` with every edge rounded (radius 0.3) has 26 faces: 6 planes, 12
quarter cylinders and 8 corner patches (each with a pole), joined along 48 shared edges
and with no free edge. Built and written to STEP inside the test
(``BRepPrimAPI_MakeBox``, ``BRepFilletAPI_MakeFillet``, ``BRepBuilderAPI_NurbsConvert``),
read with the file's topology (:func:`splinedeform.cad_body.read_body`), every face
elevated by one degree with one knot into every span, and pinched: two opposite unit point
loads at the centres of the top and bottom faces (self-equilibrated, so the free body has
an equilibrium with its mean motion held at zero).
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.boundary import edge_points
from splinedeform.pipeline_body import body_static
from splinedeform.refine import refine_surface

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

SIZE, RADIUS = (2.0, 3.0, 1.0), 0.3


def free_edges(path) -> int:
    """Free edges of the shape in a STEP file, read back by OpenCASCADE: the edges that
    bound one face only (``ShapeAnalysis_FreeBounds`` on the shape as read, without sewing
    it first)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    shape = reader.OneShape()
    faces = TopExp_Explorer(shape, TopAbs_FACE)
    assert faces.More()                                    # the file holds faces
    bounds = ShapeAnalysis_FreeBounds(shape, False, False)     # the file's own edges, unsewn
    count = 0
    for wires in (bounds.GetClosedWires(), bounds.GetOpenWires()):
        explorer = TopExp_Explorer(wires, TopAbs_EDGE)
        while explorer.More():
            count += 1
            explorer.Next()
    return count


@pytest.fixture(scope="module")
def filleted_box(tmp_path_factory):
    """The STEP file of the filleted box (module docstring)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    box = BRepPrimAPI_MakeBox(*SIZE).Shape()
    fillet = BRepFilletAPI_MakeFillet(box)
    edges = TopExp_Explorer(box, TopAbs_EDGE)
    while edges.More():
        fillet.Add(RADIUS, TopoDS.Edge(edges.Current()))
        edges.Next()
    shape = BRepBuilderAPI_NurbsConvert(fillet.Shape(), True).Shape()
    path = tmp_path_factory.mktemp("fillet") / "filleted_box.step"
    writer = STEPControl_Writer()
    assert writer.Transfer(shape, STEPControl_AsIs) == 1
    assert writer.Write(str(path)) == 1
    return path


def face_at(patches, axis: int, value: float) -> int:
    """The patch whose control points all lie on the plane ``x_axis = value``."""
    (k,) = [k for k, s in enumerate(patches)
            if np.abs(s.control_points[..., axis] - value).max() < 1e-9]
    return k


def test_a_filleted_box_deforms_as_one_body_and_its_step_file_stays_closed(
        filleted_box, tmp_path):
    from splinedeform.cad_body import read_body
    from splinedeform.export.body import write_body_step

    surfaces, topology, info = read_body(filleted_box)
    assert len(surfaces) == 26
    assert topology.counts == {"shared": 48, "boundary": 0, "seam": 0, "non_manifold": 0,
                               "off_sides": 0}
    patches = [refine_surface(s, (1, 1), (1, 1)) for s in surfaces]
    body = sd.Body(patches)
    # the refined faces still meet along the file's 48 edges, every one conforming
    assert body.summary() == {"shared": 48, "seam": 0, "boundary": 0, "non_manifold": 0,
                              "poles": 8, "non_conforming": 0}
    model = sd.BodyModel(body, sd.Material(w10=1.0, w01=1.0))
    assert model.rigid_modes == 1
    top, bottom = face_at(patches, 2, SIZE[2]), face_at(patches, 2, 0.0)
    pinch = (sd.body.OnPatch(sd.Point(*centre(patches[top]), (0.0, 0.0, -1.0)), patch=top)
             + sd.body.OnPatch(sd.Point(*centre(patches[bottom]), (0.0, 0.0, 1.0)),
                               patch=bottom))
    nets = body_static(model, pinch).control_points()
    moved = max(np.abs(net - s.control_points).max() for net, s in zip(nets, patches))
    assert moved > 0
    # no seam opens: the control points of every shared edge are merged, so the deformed
    # edges are one row of points, to round-off (measured 0), held to 1e-9 of the motion
    for i in body.interfaces:
        a, b = edge_points(nets[i.a], i.edge_a), edge_points(nets[i.b], i.edge_b)
        assert np.abs(a - (b[::-1] if i.reversed else b)).max() <= 1e-9 * moved
    # the deformed body's STEP file, sewn where the faces meet, read back by OpenCASCADE:
    # as many free edges as the source (none: a closed box)
    written = write_body_step(tmp_path / "deformed.step", patches, nets)
    assert free_edges(filleted_box) == 0
    assert free_edges(written) == free_edges(filleted_box)
    # the count sees open seams: the same faces written unsewn have both sides of every
    # one of the 48 edges free
    loose = write_body_step(tmp_path / "loose.step", patches, nets, shell=False)
    assert free_edges(loose) == 2 * 48
    # the deformed body's .3dm, read back by rhino3dm: one valid Brep of the 26 faces,
    # its 48 edges each used by two faces, as many naked edges as the source (none), solid
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    from splinedeform.export.body import write_body_3dm
    from test_cad_brep_3dm import trims_per_edge

    oriented = sd.Body(patches, body.interfaces,           # the file's outward normals
                       orientation=[-1 if r else 1 for r in info["reversed"]])
    model = r3.File3dm.Read(str(write_body_3dm(tmp_path / "deformed.3dm", patches, nets,
                                               body=oriented)))
    (obj,) = list(model.Objects)
    brep = obj.Geometry
    assert brep.IsValid and len(brep.Faces) == 26 and len(brep.Edges) == 48
    uses = trims_per_edge(brep)
    assert uses.count(1) == free_edges(filleted_box) and set(uses) == {2}
    assert brep.IsSolid


def centre(surface: sd.Surface) -> tuple[float, float]:
    """The middle of a surface's parameter domain."""
    (u0, u1), (v0, v1) = surface.domain
    return 0.5 * (u0 + u1), 0.5 * (v0 + v1)
