"""Trimmed CAD faces that share no edge in the file, joined by geometry along their trims.

Each body is written twice: once joined (OpenCASCADE's sewing: the common trim curve one
edge of both faces) and once loose (a compound of faces, each with its own edges, as
exporters write every face as its own trimmed surface). The sewn file is the check of
the matching that is independent of it: its counts come from its edges, the loose
file's from the geometry (:mod:`splinedeform.cad_join_trims`), and they must agree; and
the two bodies, clamped under a uniform load, must bend alike.

* **split**: the unit square as the disc of radius 0.3 about its centre and the square
  with that hole, two trimmed faces of one plane sharing the circle
  (:func:`test_body_trimmed_cad.split_step`);
* **beside**: the trimmed square ``[0, 1]²`` cut from a larger plane (its outer loop four
  trim edges, none on its rectangle) and the untrimmed square ``[1, 2] × [0, 1]`` beside
  it, the trim edge ``x = 1`` along the untrimmed face's side ``u0``; written to STEP and
  to ``.3dm`` (a one-face Brep beside a plain surface);
* **tall**: the same trimmed square beside the untrimmed ``[1, 2] × [-0.5, 1.5]``: the
  trim edge runs along the middle half of its side ``u0``, a stretch;
* **solids**: the L prism and the drilled box of ``tests/test_body_trim_edges_cad.py``
  (trimmed faces whose trim edges lie along untrimmed faces' sides, and along a seamed
  cylinder's circles), each face copied with its own edges (``BRepBuilderAPI_Copy``)
  into a compound: every count equals the solid's own;
* **apart**: the same two faces with the untrimmed one lifted by 0.5, and two trimmed
  squares with a gap between them: nothing is joined.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import splinedeform as sd
from splinedeform import cli
from splinedeform.cad import patch_from_surface
from splinedeform.trim.loops import PolygonLoop, TrimDomain

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

from splinedeform.cad_body import read_body  # noqa: E402
from splinedeform.cad_step import write_step  # noqa: E402
from splinedeform.scenario import build, load_scenario  # noqa: E402

from coupling_systems import CLAMPED_PLATE_CENTRE  # noqa: E402
from test_body_trimmed_cad import SCENARIO, split_step  # noqa: E402

runner = CliRunner()
#: the counts compared between a loose file and its sewn twin
COUNTED = ("shared", "boundary", "seam", "non_manifold", "off_sides")


def rectangle(x0: float, y0: float, size: tuple[float, float], z: float = 0.0
              ) -> sd.Surface:
    """``[x0, x0 + a] × [y0, y0 + b]`` at height ``z``, one bilinear cell (as OpenCASCADE
    converts a plane; the scenarios elevate and refine it), its parameters lengths."""
    plane = sd.shapes.plane(size=size, cells=(1, 1), degree=1)
    return plane.with_control_points(plane.control_points + [x0, y0, z])


def square_trim(x0: float, y0: float, corner: tuple[float, float]) -> TrimDomain:
    """The unit square with its lower left corner at ``corner`` (in space) as an outer
    loop in the parameters of a plane whose lower left corner is ``(x0, y0)``: four trim
    edges, one per side (``outer.0`` … ``outer.3``, counter-clockwise from the bottom)."""
    u, v = corner[0] - x0, corner[1] - y0
    square = PolygonLoop(np.array([[u, v], [u + 1, v], [u + 1, v + 1], [u, v + 1]]))
    return TrimDomain(square, (), ((0, 1, 2, 3),))


def beside(folder, suffix: str, sewn: bool = False, lift: float = 0.0, tall: bool = False):
    """The trimmed square ``[0, 1]²`` (on the plane ``[-0.25, 1.5] × [-0.3, 1.25]``) and
    the untrimmed ``[1, 2] × [0, 1]`` at height ``lift`` (module docstring); ``tall``:
    the untrimmed ``[1, 2] × [-0.5, 1.5]``, whose side ``u0`` the trim edge runs along
    the middle half of."""
    other = rectangle(1.0, -0.5, (1.0, 2.0)) if tall else rectangle(1.0, 0.0, (1.0, 1.0), lift)
    patches = [patch_from_surface(rectangle(-0.25, -0.3, (1.75, 1.55))),
               patch_from_surface(other)]
    trims = [square_trim(-0.25, -0.3, (0.0, 0.0)), None]
    name = (f"{'tall' if tall else 'beside'}{'_sewn' if sewn else ''}"
            f"{'_lifted' if lift else ''}{suffix}")
    if suffix == ".3dm":
        return sd.cad.write_3dm(folder / name, patches, trims=trims)
    return write_step(folder / name, patches, shell=sewn, trims=trims)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """``{name: path}``: split and beside, loose and sewn, and beside as a ``.3dm``."""
    folder = tmp_path_factory.mktemp("trimloose")
    out = {"split": folder / "split.step", "split_sewn": folder / "split_sewn.step"}
    split_step(out["split"], sewn=False)
    split_step(out["split_sewn"])
    out["beside"] = beside(folder, ".step")
    out["beside_sewn"] = beside(folder, ".step", sewn=True)
    out["tall"] = beside(folder, ".step", tall=True)
    out["tall_sewn"] = beside(folder, ".step", sewn=True, tall=True)
    try:
        import rhino3dm  # noqa: F401
    except ImportError:
        return out
    out["beside_3dm"] = beside(folder, ".3dm")
    return out


def body(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")             # the trimmed faces are read whole here
        return read_body(path)


def counts(topology) -> dict:
    return {**{k: topology.counts[k] for k in COUNTED}, "trim_edges": topology.trim_edges}


def test_the_files_are_written_loose_and_sewn(files):
    # the loose files join nothing themselves (every edge one use), the sewn ones the trim
    # curve: the premise of the comparisons below, from OpenCASCADE's own edges
    from splinedeform.cad_body import read_listing

    for name in ("split", "beside"):
        assert max(len(e["faces"]) for e in read_listing(files[name])["edges"]) == 1
        assert max(len(e["faces"]) for e in read_listing(files[f"{name}_sewn"])["edges"]) == 2


def test_loose_trimmed_faces_sharing_a_circle_are_joined_along_it(files):
    _, topology, info = body(files["split"])
    _, sewn, sewn_info = body(files["split_sewn"])
    assert sewn_info["joined_by_geometry"] == []
    # the ring (face 0) and its hole, the disc (face 1) and its outer loop: one curve
    assert info["joined_by_geometry"] == [
        {"face_a": 0, "edge_a": "hole1", "face_b": 1, "edge_b": "outer"}]
    assert info["partly_joined_by_geometry"] == []
    assert topology.counts["joined_by_geometry"] == 1
    assert counts(topology) == counts(sewn)         # integers: exact
    assert counts(topology) == {"shared": 1, "boundary": 4, "seam": 0, "non_manifold": 0,
                                "off_sides": 1, "trim_edges": {"shared": 1, "free": 0}}


def test_a_loose_trimmed_face_is_joined_to_a_loose_untrimmed_side(files):
    _, topology, info = body(files["beside"])
    _, sewn, _ = body(files["beside_sewn"])
    # the square's outer loop runs (0,0) (1,0) (1,1) (0,1): trim edge 1 is x = 1
    assert info["joined_by_geometry"] == [
        {"face_a": 0, "edge_a": "outer.1", "face_b": 1, "edge_b": "u0"}]
    assert topology.trim_joins == [(0, "outer.1", 1, "u0", True)]
    assert counts(topology) == counts(sewn)
    assert counts(topology) == {"shared": 1, "boundary": 6, "seam": 0, "non_manifold": 0,
                                "off_sides": 4, "trim_edges": {"shared": 1, "free": 3}}


def test_a_trim_edge_along_part_of_a_side_is_a_stretch(files):
    _, topology, info = body(files["tall"])
    _, sewn, _ = body(files["tall_sewn"])
    assert info["joined_by_geometry"] == []
    assert info["partly_joined_by_geometry"] == [
        {"face_a": 0, "edge_a": "outer.1", "face_b": 1, "edge_b": "u0"}]
    assert topology.trim_joins == [(0, "outer.1", 1, "u0", False)]
    assert topology.counts["partly_shared"] == topology.counts["joined_by_geometry"] == 1
    # OpenCASCADE's sewing splits the side u0 at the trim edge's ends, into the shared
    # edge and two boundary edges; the loose file's side stays one edge, coupled along
    # the stretch: the same counts but for those two pieces
    assert counts(topology) == {**counts(sewn), "boundary": counts(sewn)["boundary"] - 2}


def test_the_3dm_trimmed_face_beside_a_plain_surface_is_joined(files):
    pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    _, topology, info = body(files["beside_3dm"])
    _, sewn, _ = body(files["beside_sewn"])
    assert info["joined_by_geometry"] == [
        {"face_a": 0, "edge_a": "outer.1", "face_b": 1, "edge_b": "u0"}]
    assert topology.counts["joined_by_geometry"] == 1
    assert counts(topology) == counts(sewn)


def test_faces_that_do_not_touch_are_not_joined(tmp_path):
    _, topology, info = body(beside(tmp_path, ".step", lift=0.5))
    assert info["joined_by_geometry"] == info["partly_joined_by_geometry"] == []
    assert topology.counts["joined_by_geometry"] == 0 and topology.trim_joins == []
    assert topology.counts["shared"] == 0 and topology.trim_edges["shared"] == 0
    # two trimmed unit squares 0.2 apart, each cut from its own larger plane
    patches = [patch_from_surface(rectangle(x - 0.1, -0.1, (1.3, 1.2)))
               for x in (0.0, 1.2)]
    trims = [square_trim(x - 0.1, -0.1, (x, 0.0)) for x in (0.0, 1.2)]
    _, topology, info = body(write_step(tmp_path / "gap.step", patches, trims=trims))
    assert info["joined_by_geometry"] == [] and topology.counts["joined_by_geometry"] == 0
    assert topology.trim_edges == {"shared": 0, "free": 8}


def test_splinedeform_faces_counts_the_trim_joins(files):
    result = runner.invoke(cli.app, ["faces", "--json", str(files["split"])])
    assert result.exit_code == 0, result.output
    topology = json.loads(result.output[result.output.index("{"):])["topology"]
    assert topology["joined_by_geometry"] == 1 and topology["shared"] == 1
    assert topology["trim_joins"] == [{"a": 0, "edge_a": "hole1", "b": 1, "edge_b": "outer",
                                       "whole": True}]
    text = runner.invoke(cli.app, ["faces", str(files["split"])])
    assert text.exit_code == 0, text.output
    assert "; 1 joined by geometry" in text.output


def deflection(path, refine: int):
    """The static deflection of the body of ``path`` clamped on every boundary edge under
    a unit uniform load, sampled on a 21² parameter grid of each face's region, with the
    body's trim interfaces and shared stretches."""
    scenario = path.with_suffix(".toml")
    scenario.write_text(SCENARIO.replace("split.step", path.name)
                        .replace("refine = [11, 11]", f"refine = [{refine}, {refine}]"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        built = build(load_scenario(scenario))
    static = built.model.static(built.load)
    samples = []
    for p, surface in enumerate(built.surface.patches):
        (_, lu), (_, lv) = surface.domain
        U, V = (x.ravel() for x in np.meshgrid(np.linspace(0, lu, 21), np.linspace(0, lv, 21)))
        samples.append(static.displacement(U, V, patch=p))
    trims = [(type(i).__name__, i.a, i.b) for i in (*built.surface.trim_interfaces,
                                                     *built.surface.edge_interfaces)]
    return np.concatenate(samples), trims


#: the clamped rectangle of sides 2 : 1, centre deflection w D / (q a⁴), a the short side
#: (Timoshenko & Woinowsky-Krieger, table 35: three digits)
RECTANGLE_CENTRE = 0.00254


@pytest.mark.parametrize("name, twin", [("split", "split_sewn"), ("beside", "beside_sewn"),
                                        ("tall", "tall_sewn"), ("beside_3dm", "beside_sewn")])
def test_a_loose_clamped_plate_bends_as_its_sewn_twin(files, name, twin):
    # the same faces with the same loops, coupled along the same curve by the same
    # penalties: the loose STEP files give the sewn ones' systems (measured: no difference
    # at all), the .3dm's loop is its 3-D edge pulled back onto the face and fitted within
    # 1e-10 of the face's parameter box (measured 4e-10 of the largest deflection);
    # 1e-8 of the largest deflection bounds both
    if name.endswith("3dm"):
        pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    loose, trims = deflection(files[name], 11)
    sewn, sewn_trims = deflection(files[twin], 11)
    assert trims == sewn_trims and trims
    scale = np.abs(sewn).max()
    assert np.abs(loose - sewn).max() <= 1e-8 * scale
    # and they are the clamped plates: the square (to 1e-3, as tests/test_body_trimmed_cad
    # finds it) and the 2 × 1 rectangle (to 1e-2: the table's three digits, 2e-3, and
    # the cubic faces' discretisation)
    if name != "tall":
        reference = CLAMPED_PLATE_CENTRE if name == "split" else RECTANGLE_CENTRE
        assert abs(scale / reference - 1) < (1e-3 if name == "split" else 1e-2)


def test_validate_counts_the_trim_join_among_the_body_s_edges(files):
    scenario = files["split"].with_name("split_validate.toml")
    scenario.write_text(SCENARIO.replace("split.step", files["split"].name))
    result = runner.invoke(cli.app, ["validate", str(scenario)])
    assert result.exit_code == 0, result.output
    assert "1 shared, 4 boundary" in result.output
    assert "1 joined-by-geometry" in result.output


def loose_copy(shape):
    """A compound of copies of the faces of ``shape``, each with its own edges (the faces
    as an exporter that writes each one alone writes them)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Compound

    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    faces = TopExp_Explorer(shape, TopAbs_FACE)
    while faces.More():
        builder.Add(compound, BRepBuilderAPI_Copy(faces.Current()).Shape())
        faces.Next()
    return compound


def solids():
    """The L prism and the drilled box (module docstring), as OpenCASCADE shapes."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import (BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder,
                                 BRepPrimAPI_MakePrism)
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Vec

    polygon = BRepBuilderAPI_MakePolygon()
    for x, y in [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]:
        polygon.Add(gp_Pnt(x, y, 0))
    polygon.Close()
    base = BRepBuilderAPI_MakeFace(polygon.Wire()).Face()
    prism = BRepPrimAPI_MakePrism(base, gp_Vec(0, 0, 1.0)).Shape()
    box = BRepPrimAPI_MakeBox(2.0, 2.0, 1.0).Shape()
    drill = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 1, -0.5), gp_Dir(0, 0, 1)), 0.4, 2.0)
    return {"prism": prism, "drilled": BRepAlgoAPI_Cut(box, drill.Shape()).Shape()}


@pytest.mark.parametrize("name, joins", [("prism", (18, 4)), ("drilled", (14, 0))])
def test_a_solid_written_face_by_face_counts_as_the_solid(tmp_path, name, joins):
    from test_body_trim_edges_cad import write_step as write_shape

    shape = solids()[name]
    _, solid, _ = body(write_shape(shape, tmp_path / f"{name}_solid.step"))
    _, topology, info = body(write_shape(loose_copy(shape), tmp_path / f"{name}.step"))
    assert "joined_by_geometry" not in solid.counts
    # every edge of the solid found again: the file's counts from its edges, the loose
    # file's from the geometry (integers: exact), partly_shared included
    assert {k: v for k, v in topology.counts.items() if "joined" not in k} == solid.counts
    assert topology.trim_edges == solid.trim_edges
    assert (topology.counts["joined_by_geometry"],
            topology.counts.get("partly_joined_by_geometry", 0)) == joins
    assert len(info["joined_by_geometry"]) + len(info["partly_joined_by_geometry"]) == joins[0]
