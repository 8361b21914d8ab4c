"""A body's outputs carry each face's Brep orientation (outputs_body.py, export/body.py,
export/body_nets.py): OpenCASCADE's box, three of whose six faces its Brep marks reversed
(their outward normal is ``-(x_u × x_v)``), run from a scenario and read back by meshio.

The box is convex, so a triangle's normal points out when ``n · (c − m) > 0``, ``c`` the
triangle's centroid and ``m`` the box's centre: checked for every triangle of the OBJ
(and the OBJ's vertex normals), independently of the file's flags.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
meshio = pytest.importorskip("meshio")

from splinedeform.pipeline import run  # noqa: E402
from splinedeform.scenario import load_scenario  # noqa: E402

SIZE = (1.0, 2.0, 3.0)
CENTRE = 0.5 * np.asarray(SIZE)


@pytest.fixture(scope="module")
def inflated(tmp_path_factory):
    """The box (STEP, built here) under an internal pressure, written as OBJ, PLY, STL,
    nets and report."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    folder = tmp_path_factory.mktemp("orient")
    shape = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(*SIZE).Shape(), True).Shape()
    writer = STEPControl_Writer()
    assert writer.Transfer(shape, STEPControl_AsIs) == 1
    assert writer.Write(str(folder / "box.step")) == 1
    (folder / "box.toml").write_text(
        '[surface]\nshape = "cad"\npath = "box.step"\n\n[material]\nw10 = 1.0\nw01 = 1.0\n\n'
        '[[load]]\nkind = "pressure"\nq = 0.01\n\n[solve]\nkind = "static"\nframes = 2\n\n'
        '[output]\nformats = ["obj", "ply", "stl", "json", "npz", "report"]\nresolution = 5\n')
    result = run(load_scenario(folder / "box.toml"), folder / "out")
    return result, folder / "out"


def outward(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """``n · (c − m)`` of every triangle over ``|n| |c − m|``: +1 straight out, −1 in."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    r = (a + b + c) / 3 - CENTRE
    return np.einsum("ij,ij->i", n, r) / (np.linalg.norm(n, axis=1) * np.linalg.norm(r, axis=1))


def test_some_faces_of_the_box_are_reversed(inflated):
    result, out = inflated
    signs = result.built.surface.orientation
    assert signs.count(-1) == 3 and signs.count(1) == 3
    report = json.loads((out / "report.json").read_text())
    assert report["body"]["reversed"] == [s < 0 for s in signs]


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl"])
def test_every_triangle_of_the_meshes_faces_out(inflated, suffix):
    _, out = inflated
    mesh = meshio.read(out / f"box{suffix}")
    cosine = outward(mesh.points, mesh.cells_dict["triangle"])
    # the flat faces' triangles are seen from the centre at an angle below 72° (cosine
    # 0.32 measured, a corner triangle of a long face); one wound inwards would be < 0
    assert cosine.min() > 0.1


def test_the_obj_vertex_normals_point_out(inflated):
    _, out = inflated
    lines = (out / "box.obj").read_text().splitlines()
    points = np.array([[float(x) for x in line.split()[1:4]] for line in lines
                       if line.startswith("v ")])
    normals = np.array([[float(x) for x in line.split()[1:4]] for line in lines
                        if line.startswith("vn ")])
    assert normals.shape == points.shape
    # area-weighted means over a point's triangles, all outward: along the point's offset
    # from the centre within 90° (an edge's or corner's normal bisects its faces)
    assert np.all(np.einsum("ij,ij->i", normals, points - CENTRE) > 0)


def test_the_nets_carry_each_face_s_orientation(inflated):
    result, out = inflated
    signs = result.built.surface.orientation
    doc = json.loads((out / "box_nets.json").read_text())
    assert [doc["nets"][str(f)]["reversed"] for f in doc["faces"]] == [s < 0 for s in signs]
    with np.load(out / "box_nets.npz") as npz:
        flags = [bool(npz[f"face{f}/reversed"]) for f in npz["faces"]]
    assert flags == [s < 0 for s in signs]
