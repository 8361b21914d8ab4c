"""A body of trimmed CAD faces through a scenario: a unit square plate of two faces built by
OpenCASCADE, the square with a circular hole and the disc filling it, sharing the circle.
Each face is read with its trim loops (fitted piecewise curves), the two loops are found to
trace one curve, and the faces are coupled along it (:mod:`splinedeform.body.trimmed`);
the same under the shell on a rational plane whose NURBS weights are not a product."""

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


def split_step(path, weights=None, sewn=True):
    """The square [0, 1]² as two faces of one B-spline plane: the disc and the rest; with
    ``weights`` (3 × 3) the plane is a biquadratic on the grid of poles ``(i/2, j/2, 0)``
    with those NURBS weights (the same square, its parametrisation warped). Sewn into one
    shell (the circle one edge of both faces), or with ``sewn=False`` written as a
    compound of the two faces, each with its own edges (joined by nothing in the file)."""
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
    if weights is not None:
        import numpy as np

        from splinedeform.cad import NurbsPatch
        from splinedeform.cad_step import bspline_surface

        X, Y = np.meshgrid([0.0, 0.5, 1.0], [0.0, 0.5, 1.0], indexing="ij")
        knots = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
        square = bspline_surface(NurbsPatch((2, 2), knots, knots, np.stack([X, Y, 0 * X], -1),
                                            np.asarray(weights, dtype=float)))
    faces = []
    disc = BRepBuilderAPI_MakeFace(square, wire, True)
    ring = BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeFace(square, 1e-9).Face())
    ring.Add(TopoDS.Wire(wire.Reversed()))
    for made in (ring, disc):
        fix = ShapeFix_Face(made.Face())                    # the pcurves on the surface
        fix.Perform()
        faces.append(fix.Face())
    if sewn:
        sewing = BRepBuilderAPI_Sewing(1e-6)
        for face in faces:
            sewing.Add(face)
        sewing.Perform()
        shape = sewing.SewedShape()
    else:
        from OCP.BRep import BRep_Builder
        from OCP.TopoDS import TopoDS_Compound

        builder, shape = BRep_Builder(), TopoDS_Compound()
        builder.MakeCompound(shape)
        for face in faces:
            builder.Add(shape, face)
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
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


def test_a_shell_body_of_faces_with_general_weights_keeps_their_trims(tmp_path):
    # the same split square on a rational plane whose weights are not a product, under the
    # shell: both faces are simulated on their trimmed regions (no face taken whole, no
    # warning), coupled along the circle, and clamped on the square's edges they are the
    # clamped square plate. Its largest deflection sampled on an 81² parameter grid of the
    # disc face against Kirchhoff's centre 0.00126532 q a⁴ / D: measured 4e-4; 1e-3 bounds
    # the sampling of a flat peak (samples within about 0.006 of the centre, where w falls
    # by about 3e-4) with the discretisation of 12 × 12 quartic cells and the fitted loops
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    import numpy as np

    from splinedeform.physics.shell_model import ShellModel
    from splinedeform.rational import product_factors
    from splinedeform.scenario import build, load_scenario

    split_step(tmp_path / "split.step", [[1.0, 1.0, 1.0], [1.0, 1.5, 1.0], [1.0, 1.0, 1.2]])
    E, NU, THICKNESS = 1.0e4, 0.3, 0.02
    plate = 'w20 = 1.0\nw11 = 1.0\nw02 = 1.0\nphysics = "parametric"'
    assert plate in SCENARIO
    shell = f'physics = "shell"\nE = {E}\nnu = {NU}\nthickness = {THICKNESS}'
    (tmp_path / "split.toml").write_text(SCENARIO.replace(plate, shell))
    with warnings.catch_warnings():
        warnings.simplefilter("error")                      # both faces are trimmed
        built = build(load_scenario(tmp_path / "split.toml"))
    assert isinstance(built.model, ShellModel)
    for surface in built.surface.patches:
        assert surface.trim is not None and surface.net_weights is not None
        assert product_factors(surface.net_weights) is None
    static = built.model.static(built.load)
    disc = next(p for p, s in enumerate(built.surface.patches) if not s.trim.holes)
    grid = np.linspace(0.0, 1.0, 81)
    U, V = (x.ravel() for x in np.meshgrid(grid, grid))
    X = built.surface.patches[disc].evaluate(U, V)
    near = np.hypot(X[:, 0] - CENTRE[0], X[:, 1] - CENTRE[1]) < RADIUS - 0.01
    peak = np.abs(static.displacement(U[near], V[near], patch=disc)).max()
    D = E * THICKNESS ** 3 / (12 * (1 - NU ** 2))
    assert abs(peak * D / CLAMPED_PLATE_CENTRE - 1) < 1e-3
