"""Outputs of a body (export/body.py), read back by rhino3dm, OpenCASCADE, meshio and
ParaView, never by our own readers."""

import shutil
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.export.body import (write_body_3dm, write_body_mesh, write_body_series,
                                      write_body_step)

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
meshio = pytest.importorskip("meshio")

from body_patches import rhino3dm_box  # noqa: E402
from splinedeform.cad_body import read_body  # noqa: E402

#: samples per direction of each patch in the meshes
RESOLUTION = 5


@pytest.fixture(scope="module")
def box(tmp_path_factory):
    """A 1 × 2 × 3 box of 6 bilinear faces in inches (rhino3dm), and a deformed net per
    face: the smooth field ``d(x) = 0.01 (sin x_1, cos x_2, x_0 x_1)`` applied to the
    control points of every face, which moves the points of a shared edge alike (they are
    the same points), so the seams stay closed."""
    surfaces, topology, info = read_body(rhino3dm_box(tmp_path_factory.mktemp("box"), "Inches"))
    field = lambda P: 0.01 * np.stack([np.sin(P[..., 1]), np.cos(P[..., 2]),  # noqa: E731
                                       P[..., 0] * P[..., 1]], axis=-1)
    rest = [s.control_points for s in surfaces]
    nets = [P + field(P) for P in rest]
    return surfaces, rest, nets, info["units"]


def test_3dm_holds_every_face_in_the_file_unit(box, tmp_path):
    from splinedeform.cad import FACE_NAME

    surfaces, _, nets, units = box
    path = write_body_3dm(tmp_path / "body.3dm", surfaces, nets, units=units)
    model = r3.File3dm.Read(str(path))
    assert str(model.Settings.ModelUnitSystem).endswith("Inches")
    (obj,) = list(model.Objects)                       # one Brep, its faces named
    assert isinstance(obj.Geometry, r3.Brep) and obj.Geometry.IsValid
    assert [obj.Attributes.GetUserString(f"{FACE_NAME}{k}") for k in range(6)] == \
        [s.name for s in surfaces]
    for face, P in zip(obj.Geometry.Faces, nets):
        srf = face.UnderlyingSurface().ToNurbsSurface()
        got = np.array([[[srf.Points[i, j].X, srf.Points[i, j].Y, srf.Points[i, j].Z]
                          for j in range(srf.Points.CountV)] for i in range(srf.Points.CountU)])
        # weights 1: the numbers written, read back as doubles (1e-12 of the size for the
        # division by w = 1 openNURBS does)
        np.testing.assert_allclose(got, P, rtol=0, atol=1e-12 * 3)


def test_step_holds_every_face_in_the_file_unit(box, tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRep import BRep_Tool
    from OCP.GeomConvert import GeomConvert
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    surfaces, _, nets, units = box
    path = write_body_step(tmp_path / "body.step", surfaces, nets, units=units)
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == 1
    reader.TransferRoots()
    explorer, poles = TopExp_Explorer(reader.OneShape(), TopAbs_FACE), []
    while explorer.More():
        spline = GeomConvert.SurfaceToBSplineSurface_s(
            BRep_Tool.Surface_s(TopoDS.Face(explorer.Current())))
        poles.append(np.array([[[spline.Pole(i, j).X(), spline.Pole(i, j).Y(),
                                 spline.Pole(i, j).Z()] for j in range(1, spline.NbVPoles() + 1)]
                               for i in range(1, spline.NbUPoles() + 1)]))
        explorer.Next()
    assert len(poles) == len(nets)
    for got, P in zip(poles, nets):
        # OpenCASCADE reads every file in millimetres: inches × 25.4 (written and read back,
        # two roundings of a product: 1e-12 of the size)
        np.testing.assert_allclose(got / 25.4, P, rtol=0, atol=1e-12 * 3)
    # one shell: each of the box's 12 edges is shared by two faces (OpenCASCADE's count)
    assert _faces_per_edge(reader.OneShape()) == [2] * 12
    # and read as a body again: the 12 interfaces of the box, conforming
    _, topology, info = read_body(path)
    assert info["units"] == "in" and topology.counts["shared"] == 12
    assert len(topology.interfaces) == 12 and all(i.conforming for i in topology.interfaces)


def _faces_per_edge(shape):
    from OCP.OCP.collections import \
        IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher as EdgeMap
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp

    ancestors = EdgeMap()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    return [ancestors.FindFromIndex(k).Size() for k in range(1, ancestors.Extent() + 1)]


def test_step_faces_stay_apart_unless_sewn(box, tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.STEPControl import STEPControl_Reader

    surfaces, _, nets, units = box
    path = write_body_step(tmp_path / "faces.step", surfaces, nets, units=units, shell=False)
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == 1
    reader.TransferRoots()
    assert _faces_per_edge(reader.OneShape()) == [1] * 24      # 6 faces of 4 free edges


def test_the_mesh_is_welded_along_the_shared_edges(box, tmp_path):
    surfaces, rest, nets, _ = box
    path = write_body_mesh(tmp_path / "body.vtu", surfaces, nets, rest, resolution=RESOLUTION)
    mesh = meshio.read(path)
    r = RESOLUTION
    # six r × r grids: the 12 edges' r points counted twice, the 8 corners three times
    assert len(mesh.points) == 6 * r * r - 12 * r + 8
    triangles = mesh.cells_dict["triangle"]
    assert len(triangles) == 6 * 2 * (r - 1) ** 2
    # watertight: every triangle edge is shared by exactly two triangles
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                    triangles[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert set(counts.tolist()) == {2}
    # the displacement is the deformed surface minus the rest surface; the faces are
    # degree 1 here, so the field at a vertex lies within the field's range over the nets
    d = mesh.point_data["displacement"]
    moved = np.concatenate([(P - R).reshape(-1, 3) for P, R in zip(nets, rest)])
    assert np.all(d >= moved.min(axis=0) - 1e-15) and np.all(d <= moved.max(axis=0) + 1e-15)
    np.testing.assert_allclose(mesh.points - d,                      # back at rest: the box
                               np.clip(mesh.points - d, 0, [1, 2, 3]), atol=1e-15)


def test_a_series_lists_one_welded_mesh_per_frame(box, tmp_path):
    surfaces, rest, nets, _ = box
    times = np.array([0.0, 0.5, 1.0])
    frames = [np.stack([R + t * (P - R) for t in times]) for P, R in zip(nets, rest)]
    pvd = write_body_series(tmp_path, "body", surfaces, rest, times, frames,
                            resolution=RESOLUTION)
    entries = ET.parse(pvd).getroot().findall(".//DataSet")
    assert [float(e.get("timestep")) for e in entries] == times.tolist()
    meshes = [meshio.read(tmp_path / e.get("file")) for e in entries]
    assert {len(m.points) for m in meshes} == {6 * RESOLUTION ** 2 - 12 * RESOLUTION + 8}
    # the displacement grows linearly with t: frame 1 is half of frame 2 (exact halving of
    # the same sums, within 1e-15 of the 0.03 displacement)
    d1, d2 = (m.point_data["displacement"] for m in meshes[1:])
    np.testing.assert_allclose(d1, d2 / 2, rtol=0, atol=1e-15)
    # frame 0 is the rest state: no displacement beyond round-off of the 0.03 scale
    np.testing.assert_allclose(meshes[0].point_data["displacement"], 0.0, rtol=0, atol=1e-15)
    assert set(np.unique(meshes[0].point_data["patch"])) == set(range(6))


def test_paraview_reads_the_welded_mesh(box, tmp_path):
    pvpython = shutil.which("pvpython")
    if pvpython is None:
        pytest.skip("ParaView's pvpython is not installed")
    surfaces, rest, nets, _ = box
    path = write_body_mesh(tmp_path / "body.vtu", surfaces, nets, rest, resolution=RESOLUTION)
    script = ("from paraview.simple import XMLUnstructuredGridReader\n"
              f"r = XMLUnstructuredGridReader(FileName=[{str(path)!r}])\n"
              "r.UpdatePipeline()\n"
              "info = r.GetDataInformation()\n"
              "print(info.GetNumberOfPoints(), info.GetNumberOfCells())\n")
    out = subprocess.run([pvpython, "-c", script], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    points, cells = map(int, out.stdout.split()[-2:])
    assert (points, cells) == (6 * RESOLUTION ** 2 - 12 * RESOLUTION + 8,
                               12 * (RESOLUTION - 1) ** 2)


def test_a_body_needs_one_net_per_patch(box, tmp_path):
    surfaces, _, nets, _ = box
    with pytest.raises(InputError, match=r"a body of 6 patch\(es\) needs as many control "
                       "nets, got 5"):
        write_body_mesh(tmp_path / "x.vtu", surfaces, nets[:5])
    with pytest.raises(InputError, match="control net of patch 2 must have shape"):
        write_body_3dm(tmp_path / "x.3dm", surfaces, nets[:2] + [nets[2][:1]] + nets[3:])
