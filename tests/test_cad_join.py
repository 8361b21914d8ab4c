"""A .3dm mixing Breps and loose surfaces: the loose ones joined where their edges meet.

The file holds a Brep (rhino3dm's ``Brep.CreateFromSurface``, with its own edges, each
used by its one face: joined to nothing, so loose too) and a plain NURBS surface sharing
one edge with it. The join comes from matching their sides (:mod:`splinedeform.cad_join`),
and the report says so. Checked against the same two surfaces written as plain surfaces only (every
interface from the geometry): the same interface, the same answer.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import splinedeform as sd

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

CELLS = 4


def square(x0: float) -> sd.Surface:
    """``[x0, x0 + 1] × [0, 1]`` at ``z = 0``, bicubic on ``CELLS`` spans per direction."""
    plane = sd.shapes.plane(size=(1.0, 1.0), cells=CELLS, degree=3, knots="open")
    return plane.with_control_points(plane.control_points + [x0, 0.0, 0.0])


def rhino_surface(surface: sd.Surface):
    """The rhino3dm NURBS surface of ``surface`` (its knots without the end ones)."""
    from splinedeform.cad import patch_from_surface

    patch = patch_from_surface(surface)
    cu, cv = patch.points.shape[:2]
    srf = r3.NurbsSurface.Create(3, False, patch.degrees[0] + 1, patch.degrees[1] + 1, cu, cv)
    for i, k in enumerate(np.asarray(patch.knots_u)[1:-1]):
        srf.KnotsU[i] = float(k)
    for i, k in enumerate(np.asarray(patch.knots_v)[1:-1]):
        srf.KnotsV[i] = float(k)
    for i, j in np.ndindex(cu, cv):
        srf.Points[i, j] = r3.Point4d(*map(float, patch.points[i, j]), 1.0)
    return srf


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """``(mixed, plain)``: a Brep face and a loose surface; the two as plain surfaces."""
    folder = tmp_path_factory.mktemp("join")
    paths = []
    for name, brep in (("mixed", True), ("plain", False)):
        model = r3.File3dm()
        left, right = rhino_surface(square(0.0)), rhino_surface(square(1.0))
        if brep:
            model.Objects.AddBrep(r3.Brep.CreateFromSurface(left))
        else:
            model.Objects.AddSurface(left)
        model.Objects.AddSurface(right)
        path = folder / f"{name}.3dm"
        assert model.Write(str(path), 7)
        paths.append(path)
    return paths


def test_the_loose_surface_is_joined_to_the_brep_face_by_geometry(files):
    from splinedeform.cad_body import read_body

    mixed, plain = files
    surfaces, topology, info = read_body(mixed)
    assert len(surfaces) == 2
    (joined,) = topology.interfaces                      # the file has none between them
    assert {(joined.a, joined.edge_a), (joined.b, joined.edge_b)} == {(0, "u1"), (1, "u0")}
    assert joined.conforming and not joined.reversed
    assert info["joined_by_geometry"] == [{"face_a": 0, "edge_a": "u1", "face_b": 1,
                                           "edge_b": "u0"}]
    # the Brep's 4 edges are each used once: a Brep of one face joined to nothing, loose
    # as the plain surface is; the matching joins its u1 with the plain surface's u0 and
    # leaves the other 3 sides of each free: 1 shared, 6 boundary
    assert topology.counts == {"shared": 1, "boundary": 6, "seam": 0, "non_manifold": 0,
                               "off_sides": 0, "joined_by_geometry": 1}
    # a file of plain surfaces only: the same matching, the same join listed
    plain_topology, plain_info = read_body(plain)[1:]
    assert plain_info["joined_by_geometry"] == info["joined_by_geometry"]
    assert plain_topology.counts == topology.counts


def test_the_mixed_body_deforms_as_the_plain_one(files):
    from splinedeform.cad_body import read_body

    answers = []
    for path in files:
        surfaces, topology, _ = read_body(path)
        body = sd.Body(surfaces, topology.interfaces or None)
        assert body.summary()["shared"] == 1 and body.summary()["boundary"] == 6
        model = sd.BodyModel(body, sd.Material(w10=1.0, w01=1.0), boundary="clamped")
        answers.append(model.static(sd.Uniform((0.0, 0.0, 1.0))).control_points())
    (a0, a1), (b0, b1) = answers
    # the same matrices and map: the same solve, to round-off of the displacement (0.1)
    for x, y in ((a0, b0), (a1, b1)):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-12)
    # the shared edge stays closed: the merged control points are one
    np.testing.assert_allclose(a0[-1], a1[0], rtol=0, atol=1e-14)
    assert np.abs(a0[..., 2]).max() > 1e-2                 # and it did move


def test_a_scenario_reports_the_edges_joined_by_geometry(files, tmp_path):
    import shutil

    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    mixed = files[0]
    shutil.copy(mixed, tmp_path / mixed.name)
    path = tmp_path / "mixed.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{mixed.name}"\n'
                    '[material]\nw10 = 1.0\nw01 = 1.0\n[boundary]\nu0 = "clamped"\n'
                    'u1 = "clamped"\nv0 = "clamped"\nv1 = "clamped"\n'
                    '[[load]]\nkind = "uniform"\nforce = [0.0, 0.0, 1.0]\n'
                    '[solve]\nkind = "static"\nframes = 2\n[output]\nformats = ["report"]\n')
    run(load_scenario(path), tmp_path / "out")
    body = json.loads((tmp_path / "out" / "report.json").read_text())["body"]
    assert body["topology"]["joined_by_geometry"] == 1
    assert body["topology"]["shared"] == 1 and body["interfaces"] == 1


def test_the_faces_command_lists_the_joins_of_plain_surfaces(files):
    from typer.testing import CliRunner

    from splinedeform import cli

    runner = CliRunner()
    for path in files:
        result = runner.invoke(cli.app, ["faces", str(path)])
        assert result.exit_code == 0, result.output
        assert ("edges: 1 shared, 6 boundary, 0 seam(s), 0 non-manifold; 1 interface(s), "
                "1 conforming; 1 joined by geometry\n") in result.output
        result = runner.invoke(cli.app, ["faces", "--json", str(path)])
        topology = json.loads(result.output)["topology"]
        # counts are integers: compared exactly
        assert (topology["joined_by_geometry"], topology["shared"]) == (1, 1)
        assert [(i["a"], i["edge_a"], i["b"], i["edge_b"]) for i in topology["interfaces"]] \
            == [(0, "u1", 1, "u0")]


def test_a_file_body_reports_its_poles_beside_the_files_edge_counts():
    """Two hemispheres (a pole at each end of v, both shared): the file's counts say nothing
    of poles, the body's own topology finds them; the report's counts carry both (integers,
    compared to half a unit)."""
    import math

    from body_patches import hemisphere
    from splinedeform.scenario.body import FileBody

    patches = [hemisphere(1.0, 0.0), hemisphere(1.0, math.pi)]
    body = FileBody(patches, sd.Body(patches).interfaces, (0, 1),
                    {"shared": 2, "boundary": 0, "seam": 0, "non_manifold": 0})
    assert abs(body.counts["poles"] - body.summary()["poles"]) < 0.5
    assert body.counts["poles"] >= 1.5 and abs(body.counts["shared"] - 2) < 0.5
    assert abs(body.counts["non_conforming"]) < 0.5
