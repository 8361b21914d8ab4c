"""A body of trimmed CAD faces through a scenario: a unit square plate of two faces built by
OpenCASCADE, the square with a circular hole and the disc filling it, sharing the circle.
Each face is read with its trim loops (fitted piecewise curves), the two loops are found to
trace one curve, and the faces are coupled along it (:mod:`splinedeform.body.trimmed`)."""

import json
import warnings

import pytest
from typer.testing import CliRunner

from splinedeform import cli

from coupling_systems import CLAMPED_PLATE_CENTRE

CENTRE, RADIUS = (0.5, 0.5), 0.3

SCENARIO = """
[surface]
shape = "cad"
path = "split.step"
elevate = [2, 2]
refine = [11, 11]

[material]
w20 = 1.0
w11 = 1.0
w02 = 1.0
physics = "parametric"

[boundary]
u0 = "clamped"
u1 = "clamped"
v0 = "clamped"
v1 = "clamped"

[[load]]
kind = "uniform"
force = [0, 0, 1]

[solve]
kind = "static"
frames = 2

[output]
formats = ["report", "obj"]
resolution = 17
"""


def split_step(path):
    """The square [0, 1]² as two faces of one B-spline plane: the disc and the rest."""
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace,
                                    BRepBuilderAPI_MakeWire, BRepBuilderAPI_Sewing)
    from OCP.Geom import Geom_Plane, Geom_RectangularTrimmedSurface
    from OCP.GeomConvert import GeomConvert
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pln, gp_Pnt
    from OCP.ShapeFix import ShapeFix_Face
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS

    circle = gp_Circ(gp_Ax2(gp_Pnt(*CENTRE, 0.0), gp_Dir(0, 0, 1)), RADIUS)
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire()
    plane = Geom_RectangularTrimmedSurface(
        Geom_Plane(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))), 0.0, 1.0, 0.0, 1.0)
    square = GeomConvert.SurfaceToBSplineSurface_s(plane)   # its box is the whole square
    faces = []
    disc = BRepBuilderAPI_MakeFace(square, wire, True)
    ring = BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeFace(square, 1e-9).Face())
    ring.Add(TopoDS.Wire(wire.Reversed()))
    for made in (ring, disc):
        fix = ShapeFix_Face(made.Face())                    # the pcurves on the surface
        fix.Perform()
        faces.append(fix.Face())
    sewing = BRepBuilderAPI_Sewing(1e-6)
    for face in faces:
        sewing.Add(face)
    sewing.Perform()
    writer = STEPControl_Writer()
    writer.Transfer(sewing.SewedShape(), STEPControl_AsIs)
    writer.Write(str(path))


def test_a_plate_of_a_disc_face_and_a_holed_face_from_a_step_file(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    split_step(tmp_path / "split.step")
    scenario = tmp_path / "split.toml"
    scenario.write_text(SCENARIO)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                      # both faces are trimmed
        result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o",
                                              str(tmp_path / "out"), "-q"])
    assert result.exit_code == 0, result.output
    assert "whole underlying surface" not in result.output
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    # the largest displacement is the disc's centre: within 0.1 % of the closed form
    # (cubic faces of 12 × 12 cells reach 7e-5, the loops fitted to 1e-10)
    largest = report["solver"]["max displacement"]
    assert abs(largest / CLAMPED_PLATE_CENTRE - 1) < 1e-3
    # the disc's probe is its centre, a point of the 17 × 17 output grid where the largest
    # displacement was found: the same point evaluated twice, 1e-6 for round-off
    assert report["probes"]["face 1 centre dz"][-1] == pytest.approx(largest, rel=1e-6)
