"""Solids from OpenCASCADE whose faces share trim edges, deformed as one body.

* The drilled box: ``BRepPrimAPI_MakeBox`` 2 × 2 × 1 less ``BRepPrimAPI_MakeCylinder``
  of radius 0.4 through its middle (``BRepAlgoAPI_Cut``): 7 faces, the top and the bottom
  each a square with a circular hole (outer loop 4 trim edges on its parameter
  rectangle, inner loop the circle), 4 untrimmed sides and the cylinder's wall, whose
  edges ``v0`` and ``v1`` are the two circles.
* The L prism: an L-shaped polygon extruded (``BRepPrimAPI_MakePrism``): its top and
  bottom are L-shaped trimmed faces (6 trim edges each, on a plane whose parameter
  rectangle is the L's box), each trim edge the top or bottom iso-edge of a side face.

Each is read from the STEP file the test writes, refined (``elevate = [2, 2]``,
``refine = [3, 3]``: cubic faces), and pressed from inside by a unit pressure, a membrane
(``w10 = w01 = 1``, parametric): the free body's equilibrium with its mean motion held
at zero (:func:`splinedeform.pipeline_body.body_static`).
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

import splinedeform as sd
from splinedeform import cli
from splinedeform.body.trim_edges import ISO_SEGMENTS, edge_curve, side
from splinedeform.physics import coupling
from splinedeform.physics.coupling_curves import curve_line, curve_points
from splinedeform.pipeline_body import body_static
from splinedeform.scenario import build, load_scenario

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

SCENARIO = """
[surface]
shape = "cad"
path = "{path}"
elevate = [2, 2]
refine = [{refine}, {refine}]

[material]
w10 = 1.0
w01 = 1.0
physics = "parametric"

[[load]]
kind = "pressure"
q = 1.0

[solve]
kind = "static"
frames = 2

[output]
formats = ["report", "obj", "vtu"]
resolution = 9
"""


def write_step(shape, path):
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    writer.Write(str(path))
    return path


@pytest.fixture(scope="module")
def drilled_box(tmp_path_factory):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    box = BRepPrimAPI_MakeBox(2.0, 2.0, 1.0).Shape()
    drill = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1.0, 1.0, -0.5), gp_Dir(0, 0, 1)),
                                     0.4, 2.0).Shape()
    cut = BRepAlgoAPI_Cut(box, drill)
    cut.Build()
    return write_step(cut.Shape(), tmp_path_factory.mktemp("drilled") / "drilled.step")


@pytest.fixture(scope="module")
def l_prism(tmp_path_factory):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec

    polygon = BRepBuilderAPI_MakePolygon()
    for x, y in ((0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)):
        polygon.Add(gp_Pnt(x, y, 0))
    polygon.Close()
    face = BRepBuilderAPI_MakeFace(polygon.Wire(), True).Face()
    prism = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 1.0)).Shape()
    return write_step(prism, tmp_path_factory.mktemp("prism") / "prism.step")


def built_body(step, refine=3):
    """The scenario's body and model (the faces trimmed where the file trims them)."""
    scenario = step.parent / f"{step.stem}_{refine}.toml"
    scenario.write_text(SCENARIO.format(path=step.name, refine=refine))
    built = build(load_scenario(scenario))
    return built.surface, built.model, built.load


def stretches(body):
    """Every coupled stretch as ``(a, edge_a, part_a, b, edge_b, part_b)``: the iso-edge
    interfaces as whole segments of the rectangles' polygons (b's run the other way where
    the two edges' parameters do, the polygon running v0 and u1 forwards, v1 and u0
    backwards), then the trim-edge stretches."""
    out = []
    for i in body.interfaces:
        ka, kb = ISO_SEGMENTS[i.edge_a], ISO_SEGMENTS[i.edge_b]
        forward = ((i.edge_a in ("v0", "u1")) == (i.edge_b in ("v0", "u1"))) != i.reversed
        out.append((i.a, i.edge_a, (ka, ka + 1.0), i.b, i.edge_b,
                    (kb, kb + 1.0) if forward else (kb + 1.0, kb)))
    out += [(i.a, i.edge_a, i.part_a, i.b, i.edge_b, i.part_b) for i in body.edge_interfaces]
    return out


def sides(body, a, ea, pa, b, eb, pb):
    return (side(body.patches, edge_curve(body.patches, a, ea), pa),
            side(body.patches, edge_curve(body.patches, b, eb), pb))


def gaps(body, static, samples=101):
    """Per stretch the largest jump of the displacement at the same points of the two
    faces (b's parameters by closest-point projection from the linear map of the ends)."""
    out = []
    for a, ea, pa, b, eb, pb in stretches(body):
        A, B = sides(body, a, ea, pa, b, eb, pb)
        t = np.linspace(pa[0], pa[1], samples)
        s = B.closest(A.position(t)[0], pb[0] + (t - pa[0]) * (pb[1] - pb[0]) / (pa[1] - pa[0]))
        ua, ub = curve_points(A.loop, t)[0], curve_points(B.loop, s)[0]
        jump = (static.displacement(ua[:, 0], ua[:, 1], patch=a)
                - static.displacement(ub[:, 0], ub[:, 1], patch=b))
        out.append(float(np.abs(jump).max()))
    return np.array(out)


def projected_jump(body, static, stretch):
    """The largest ``|Π (d_a − d_b)|`` at the quadrature points of a trim-edge stretch:
    the part of the jump in the trace space that the penalty measures."""
    from splinedeform.body.interface import EDGES

    a, ea, pa, b, eb, pb = stretch
    A, B = sides(body, *stretch)
    line, _ = curve_line(A, B, "", lambda t: pb[0] + (np.asarray(t) - pa[0])
                         * ((pb[1] - pb[0]) / (pa[1] - pa[0])), 1 if eb in EDGES else 0)
    nets = static.net_displacement()
    jump = (line.sides[0].values @ nets[a].reshape(-1, 3)
            - line.sides[1].values @ nets[b].reshape(-1, 3))
    Phi = line.space(0).toarray()
    W = line.weights[:, None]
    return float(np.abs(Phi @ np.linalg.solve(Phi.T @ (W * Phi), Phi.T @ (W * jump))).max())


def solved(body, model, load, scale=1.0):
    """The static solution, on a model rebuilt with the penalty factor scaled."""
    if scale != 1.0:
        previous = coupling.PENALTY
        coupling.PENALTY = previous * scale
        try:
            model = sd.BodyModel(body, model.material, physics="parametric")
        finally:
            coupling.PENALTY = previous
    static = body_static(model, load)
    largest = max(np.abs(d).max() for d in static.net_displacement())
    return static, largest


def test_the_drilled_box_is_one_body(drilled_box):
    body, model, load = built_body(drilled_box)
    # the two holes are coupled to the wall's circles, each as one stretch of the whole
    # circle; the top's and bottom's rectangles meet the sides along iso-edges, coupled by
    # penalties (a trimmed face merges no control points): 8 non-conforming interfaces
    assert sorted((i.edge_a, i.edge_b) for i in body.edge_interfaces) == [
        ("hole1", "v0"), ("hole1", "v1")]
    assert body.summary()["boundary"] == 0 and body.summary()["non_conforming"] == 8
    assert body.trim_summary() == {"shared": 2, "free": 0, "stretches": 2}
    assert model.rigid_modes == 1                      # one connected body, membrane
    static, largest = solved(body, model, load)
    stiff, largest_stiff = solved(body, model, load, 10.0)
    first, second = gaps(body, static), gaps(body, stiff)
    # every shared edge: the gap below 1e-3 of the largest displacement (the penalty's
    # α = C T / h, C = 1e5, leaves 4.9e-6 on the iso-edges; the holes 4.2e-4, below)
    assert first.max() < 1e-3 * largest
    # iso-edges (both traces in the finer edge's space): the gap falls a decade with C
    # (measured 9.98 to 10.0; bar [7, 13]); merged edges and the seam are shut to round-off
    iso = len(body.interfaces)
    moved = first[:iso] > 1e-12 * largest
    assert moved.sum() == 8
    assert np.all((7 < first[:iso][moved] / second[:iso][moved])
                  & (first[:iso][moved] / second[:iso][moved] < 13))
    assert np.all(first[:iso][~moved] < 1e-12 * largest)
    # the holes: the penalty measures the jump in the wall's own edge space (its rational
    # quartic of 12 spans); there it falls a decade (1.3e-5 → 1.3e-6 of the largest
    # displacement), while the gap is the part of the top's trace that space cannot hold
    # (its cubic cells' crossings of the circle): the same 4.2e-4 for both factors
    for k, stretch in enumerate(stretches(body)[iso:]):
        ratio = projected_jump(body, static, stretch) / projected_jump(body, stiff, stretch)
        assert 7 < ratio < 13
        assert abs(second[iso + k] / first[iso + k] - 1) < 0.1
    # and that part is a discretisation error: with 7 knots per span instead of 3 it is
    # 1.4e-4 of the largest displacement, less than half
    fine_body, fine_model, fine_load = built_body(drilled_box, refine=7)
    fine, fine_largest = solved(fine_body, fine_model, fine_load)
    fine_gaps = gaps(fine_body, fine)[len(fine_body.interfaces):]
    assert fine_gaps.max() / fine_largest < 0.5 * first[iso:].max() / largest
    # the displacement changes by 3e-6 of itself over the decade of C
    assert abs(largest_stiff / largest - 1) < 1e-4


def test_the_l_prism_couples_every_trim_edge_to_a_side(l_prism):
    body, model, load = built_body(l_prism)
    # each of the 12 trim edges of the top and the bottom lies along the whole top or
    # bottom iso-edge of one of the 6 sides
    assert len(body.edge_interfaces) == 12
    assert body.trim_summary() == {"shared": 12, "free": 0, "stretches": 12}
    assert {i.edge_b for i in body.edge_interfaces} == {"v0", "v1"}
    assert body.summary()["boundary"] == 0
    static, largest = solved(body, model, load)
    stiff, _ = solved(body, model, load, 10.0)
    first, second = gaps(body, static), gaps(body, stiff)
    # the sides meet each other along merged edges (round-off); every trim edge's gap is
    # the penalty's, 0.9e-6 to 2.4e-6 of the largest displacement, and falls a decade
    # with C (ratios 10.0; bar [7, 13])
    trims = first[len(body.interfaces):]
    assert first.max() < 1e-3 * largest
    assert np.all((7 < trims / second[len(body.interfaces):])
                  & (trims / second[len(body.interfaces):] < 13))


def test_a_scenario_run_of_the_drilled_box(drilled_box, tmp_path):
    shutil.copy(drilled_box, tmp_path / "drilled.step")
    scenario = tmp_path / "drilled.toml"
    scenario.write_text(SCENARIO.format(path="drilled.step", refine=3))
    faces = CliRunner().invoke(cli.app, ["faces", str(drilled_box)])
    assert faces.exit_code == 0, faces.output
    assert "2 on trimming loops (2 shared by two faces, 0 free)" in faces.output
    result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o", str(tmp_path / "out"),
                                          "-q"])
    assert result.exit_code == 0, result.output
    assert "whole underlying surface" not in result.output
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["body"]["trim edges"] == {"shared": 2, "free": 0, "stretches": 2}
    assert report["body"]["patches"] == 7
    written = {p.suffix for p in (tmp_path / "out").iterdir()}
    assert {".json", ".md", ".obj"} <= written
    # the deformed body's mesh holds the 7 faces, welded: one vertex list
    obj = next((tmp_path / "out").glob("*.obj")).read_text()
    assert sum(line.startswith("v ") for line in obj.splitlines()) > 7 * 9
