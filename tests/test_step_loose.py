"""STEP faces that share no edge, joined by geometry as a ``.3dm``'s plain surfaces are.

OpenCASCADE writes the faces (:func:`splinedeform.cad_step.write_step`): as a compound of
separate faces, each with its own four edges (loose: the file joins them to nothing), and
the same faces sewn into one shell (``shell=True``: the file's own shared edges). Two
bodies of the clamped unit square, each face a cubic plane whose parameters are lengths
(:func:`splinedeform.shapes.plane`):

* **halves**: ``[0, ½] × [0, 1]`` and ``[½, 1] × [0, 1]``, ``4 × 8`` cubic cells each;
* **tee**: the left half (``8 × 16`` cells) and the right half split at ``y = ½`` into
  two squares (``4 × 4`` each), so that the left face's side ``u1`` shares one half with
  each right face's ``u0`` (a T-junction) and the right faces share a whole side.

The sewn files are the check of the matching that is independent of it: OpenCASCADE's
sewing finds the same shared edges, T-junctions included, and the loose file's counts
from the geometry equal the sewn file's from its edges. The deflections are compared with
the one-patch square of :mod:`coupling_systems` (its own assembly) and with the same
bodies built from the patches directly (:class:`splinedeform.Body`, every interface found
by the body itself).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

import splinedeform as sd
from splinedeform import cli
from splinedeform.cad import patch_from_surface

from coupling_systems import PLATE, single

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

from splinedeform.cad_body import read_body  # noqa: E402
from splinedeform.cad_step import write_step  # noqa: E402

runner = CliRunner()
LOAD = sd.Uniform((0.0, 0.0, 1.0))
#: the clamped square's centre deflection w D / (q a⁴) (Timoshenko & Woinowsky-Krieger)
REFERENCE = 0.00126532


def rectangle(x0: float, y0: float, size: tuple[float, float], cells: tuple[int, int]
              ) -> sd.Surface:
    """``[x0, x0 + a] × [y0, y0 + b]`` at ``z = 0``, cubic, its parameters lengths."""
    plane = sd.shapes.plane(size=size, cells=cells)
    return plane.with_control_points(plane.control_points + [x0, y0, 0.0])


def halves() -> list[sd.Surface]:
    return [rectangle(x, 0.0, (0.5, 1.0), (4, 8)) for x in (0.0, 0.5)]


def tee() -> list[sd.Surface]:
    return [rectangle(0.0, 0.0, (0.5, 1.0), (8, 16))] + [
        rectangle(0.5, y, (0.5, 0.5), (4, 4)) for y in (0.0, 0.5)]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """``{name: path}``: halves and tee, loose and sewn."""
    folder = tmp_path_factory.mktemp("loose")
    out = {}
    for name, make in (("halves", halves), ("tee", tee)):
        patches = [patch_from_surface(s) for s in make()]
        out[name] = write_step(folder / f"{name}.step", patches)
        out[f"{name}_sewn"] = write_step(folder / f"{name}_sewn.step", patches, shell=True)
    return out


def sides(interface) -> set[tuple[int, str]]:
    return {(interface.a, interface.edge_a), (interface.b, interface.edge_b)}


def test_loose_halves_are_joined_where_their_sides_meet(files):
    surfaces, topology, info = read_body(files["halves"])
    (joined,) = topology.interfaces                   # the file has no edge between them
    assert sides(joined) == {(0, "u1"), (1, "u0")}
    assert joined.conforming and not joined.reversed
    assert info["joined_by_geometry"] == [{"face_a": 0, "edge_a": "u1", "face_b": 1,
                                           "edge_b": "u0"}]
    assert info["partly_joined_by_geometry"] == []
    # counts are integers (compared exactly): the sewn file's, from its edges, and one
    # join found by geometry
    sewn_surfaces, sewn, sewn_info = read_body(files["halves_sewn"])
    assert sewn.counts == {"shared": 1, "boundary": 6, "seam": 0, "non_manifold": 0,
                           "off_sides": 0}
    assert topology.counts == {**sewn.counts, "joined_by_geometry": 1}
    # the sewn file keeps its own topology: the same interface, nothing from geometry
    assert [sides(i) for i in sewn.interfaces] == [sides(joined)]
    assert sewn_info["joined_by_geometry"] == [] and sewn_info["partly_joined_by_geometry"] == []
    assert "joined_by_geometry" not in sewn.counts


def test_a_loose_tee_is_joined_with_its_t_junction_as_stretches(files):
    surfaces, topology, info = read_body(files["tee"])
    # the right faces' common side is a whole interface; the left face's u1 shares a
    # stretch with each right face's u0
    (joined,) = topology.interfaces
    assert sides(joined) == {(1, "v1"), (2, "v0")} and joined.conforming
    assert sorted(topology.stretches) == [(0, "u1", 1, "u0"), (0, "u1", 2, "u0")]
    assert info["partly_joined_by_geometry"] == [
        {"face_a": a, "edge_a": ea, "face_b": b, "edge_b": eb}
        for a, ea, b, eb in topology.stretches]
    # integers, exactly: OpenCASCADE's sewing of the same faces finds 3 shared edges (2
    # of them along part of the left face's side) and 7 boundary edges
    sewn = read_body(files["tee_sewn"])[1]
    assert {k: sewn.counts[k] for k in ("shared", "boundary", "partly_shared")} == {
        "shared": 3, "boundary": 7, "partly_shared": 2}
    assert topology.counts == {**sewn.counts, "joined_by_geometry": 3,
                               "partly_joined_by_geometry": 2}
    # the body made with these interfaces couples exactly the stretches counted
    body = sd.Body(surfaces, topology.interfaces)
    assert sorted((i.a, i.edge_a, i.b, i.edge_b) for i in body.edge_interfaces) == \
        sorted(topology.stretches)
    assert body.summary()["partly_shared"] == 2 and body.summary()["boundary"] == 7


def centre(body: sd.Body, physics: str = "parametric") -> float:
    """Centre deflection of the clamped body under a unit load, read on face 0."""
    model = sd.BodyModel(body, PLATE, boundary="clamped", physics=physics)
    return float(model.static(LOAD).displacement(0.5, 0.5, patch=0)[2])


def test_the_loose_halves_bend_as_the_single_square(files):
    surfaces, topology, _ = read_body(files["halves"])
    model = sd.BodyModel(sd.Body(surfaces, topology.interfaces), PLATE, boundary="clamped",
                         physics="parametric")
    static = model.static(LOAD)
    w = float(static.displacement(0.5, 0.5, patch=0)[2])
    smooth = single(8, PLATE, "clamped")
    # merged control points and the exact C1 tie: the halves' space is the 8 × 8 patch's
    # with u = 1/2 a double knot, and the symmetric answer is the smooth patch's
    # (tests/test_body_coupling.py). Held to 1e-10 (measured 2e-14): the STEP file's 12
    # significant digits move the geometry by 5e-13 of itself, in systems of condition ~1e2
    assert abs(w - smooth) <= 1e-10 * smooth
    assert abs(w / REFERENCE - 1) <= 3e-4        # and 8 × 8 cells' discretisation: 1.4e-4
    # merged, not coupled by penalties (as the faces were before they were joined: a jump
    # of 1e-6 of w): one set of control points along x = 1/2, the same numbers on both
    # sides to round-off of evaluating them (1e-12 of w)
    v = np.linspace(0.0, 1.0, 21)
    jump = (static.displacement(np.full(21, 0.5), v, patch=0)
            - static.displacement(np.zeros(21), v, patch=1))
    assert np.abs(jump).max() <= 1e-12 * abs(w)


def test_the_loose_tee_bends_as_the_single_square(files):
    surfaces, topology, _ = read_body(files["tee"])
    w = centre(sd.Body(surfaces, topology.interfaces))
    # the same patches as a body that finds every interface and stretch itself: the same
    # matrices up to the file's round-off (5e-13 of the geometry), amplified by the
    # stretch penalties (factor 1e5 on the stiffness): measured 9e-11, held to 1e-8
    direct = centre(sd.Body(tee()))
    assert abs(w - direct) <= 1e-8 * abs(direct)
    # against the one-patch square: each is within its discretisation error of the
    # closed form (8 × 8 cells: 1.4e-4 below; the tee: 7e-5, tests/test_body_tjunction.py),
    # so they differ by less than 3e-4 of it (measured 6.5e-5)
    smooth = single(8, PLATE, "clamped")
    assert abs(w - smooth) <= 3e-4 * REFERENCE
    assert abs(w / REFERENCE - 1) <= 3e-4


def faces_output(path, *flags: str) -> str:
    result = runner.invoke(cli.app, ["faces", *flags, str(path)])
    assert result.exit_code == 0, result.output
    return result.output


def test_the_faces_command_lists_the_geometric_joins(files):
    assert ("edges: 1 shared, 6 boundary, 0 seam(s), 0 non-manifold; 1 interface(s), "
            "1 conforming; 1 joined by geometry\n") in faces_output(files["halves"])
    assert ("edges: 3 shared, 7 boundary, 0 seam(s), 0 non-manifold, 2 of them along part "
            "of a side (T-junctions, coupled as stretches); 1 interface(s), 1 conforming; "
            "3 joined by geometry (2 of them along part of a side)\n"
            ) in faces_output(files["tee"])
    topology = json.loads(faces_output(files["tee"], "--json"))["topology"]
    assert (topology["joined_by_geometry"], topology["partly_joined_by_geometry"]) == (3, 2)
    assert (topology["shared"], topology["boundary"], topology["partly_shared"]) == (3, 7, 2)
    assert [(i["a"], i["edge_a"], i["b"], i["edge_b"]) for i in topology["interfaces"]] == [
        (1, "v1", 2, "v0")]
    assert sorted((s["a"], s["edge_a"], s["b"], s["edge_b"]) for s in topology["stretches"]) \
        == [(0, "u1", 1, "u0"), (0, "u1", 2, "u0")]
    # a file that joins its faces itself: its own topology, nothing joined by geometry
    for name in ("halves_sewn", "tee_sewn"):
        assert "joined by geometry" not in faces_output(files[name])
        topology = json.loads(faces_output(files[name], "--json"))["topology"]
        assert "joined_by_geometry" not in topology and "stretches" not in topology


def test_a_loose_face_is_joined_to_a_shell_s_free_side(tmp_path):
    """A sewn shell of the two halves and a loose face ``[1, 1.5] × [0, 1]`` beside it,
    in one compound: the shell keeps the file's interface, the loose face is joined to
    the shell's free side ``u1`` of face 1 by geometry."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    from splinedeform.cad_step import bspline_surface

    faces = [BRepBuilderAPI_MakeFace(bspline_surface(patch_from_surface(s)), 1e-9).Face()
             for s in halves() + [rectangle(1.0, 0.0, (0.5, 1.0), (4, 8))]]
    sewing = BRepBuilderAPI_Sewing(1e-7)
    for face in faces[:2]:
        sewing.Add(face)
    sewing.Perform()
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    builder.Add(compound, sewing.SewedShape())
    builder.Add(compound, faces[2])
    writer = STEPControl_Writer()
    assert writer.Transfer(compound, STEPControl_AsIs) == 1
    path = tmp_path / "mixed.step"
    assert writer.Write(str(path)) == 1

    surfaces, topology, info = read_body(path)
    assert len(surfaces) == 3
    first, second = topology.interfaces                 # the file's first
    assert sides(first) == {(0, "u1"), (1, "u0")}
    assert sides(second) == {(1, "u1"), (2, "u0")}
    assert info["joined_by_geometry"] == [{"face_a": 1, "edge_a": "u1", "face_b": 2,
                                           "edge_b": "u0"}]
    # integers, exactly: the shell's 6 free edges less the one joined, and the loose
    # face's 3 free sides
    assert topology.counts == {"shared": 2, "boundary": 8, "seam": 0, "non_manifold": 0,
                               "off_sides": 0, "joined_by_geometry": 1}


def test_a_scenario_on_the_loose_tee_uses_and_reports_the_joins(files, tmp_path):
    import shutil

    shutil.copy(files["tee"], tmp_path / "tee.step")
    path = tmp_path / "tee.toml"
    path.write_text('[surface]\nshape = "cad"\npath = "tee.step"\n'
                    '[material]\nw10 = 1.0\nw01 = 1.0\n[boundary]\nu0 = "clamped"\n'
                    'u1 = "clamped"\nv0 = "clamped"\nv1 = "clamped"\n'
                    '[[load]]\nkind = "uniform"\nforce = [0.0, 0.0, 1.0]\n'
                    '[solve]\nkind = "static"\nframes = 2\n[output]\nformats = ["report"]\n')
    result = runner.invoke(cli.app, ["validate", str(path)])
    assert result.exit_code == 0, result.output
    assert ("3 shared, 7 boundary, 0 seam, 0 non-manifold, 0 off-sides, 2 partly-shared, "
            "3 joined-by-geometry, 2 partly-joined-by-geometry") in result.output
    result = runner.invoke(cli.app, ["run", str(path), "-o", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    body = json.loads((tmp_path / "out" / "report.json").read_text())["body"]
    # integers, exactly: the body merges the one whole interface
    assert body["interfaces"] == 1
    assert (body["topology"]["joined_by_geometry"],
            body["topology"]["partly_joined_by_geometry"]) == (3, 2)


def test_three_loose_faces_on_one_side_are_one_non_manifold_edge(tmp_path):
    """Three pages of a book, ``x = 0`` their common side: one curve where three sides
    meet, counted as the body counts it (:meth:`splinedeform.Body.summary`)."""
    pages = []
    for angle in (0.0, 2.0, 4.0):
        page = sd.shapes.plane(size=(1.0, 1.0), cells=2)
        P = page.control_points
        pages.append(page.with_control_points(np.stack(
            [P[..., 0] * np.cos(angle), P[..., 1], P[..., 0] * np.sin(angle)], axis=-1)))
    path = write_step(tmp_path / "book.step", [patch_from_surface(p) for p in pages])
    surfaces, topology, info = read_body(path)
    # integers, exactly: each pair of the three u0 sides is an interface, the curve is
    # one non-manifold edge and no shared one, as the body of the pages counts them
    found = sd.Body(pages).summary()
    assert (found["non_manifold"], found["shared"], found["boundary"]) == (1, 0, 9)
    assert {k: topology.counts[k] for k in ("non_manifold", "shared", "boundary")} == {
        "non_manifold": 1, "shared": 0, "boundary": 9}
    assert topology.counts["joined_by_geometry"] == 3
    assert {frozenset(sides(i)) for i in topology.interfaces} == {
        frozenset({(a, "u0"), (b, "u0")}) for a, b in ((0, 1), (0, 2), (1, 2))}
