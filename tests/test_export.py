"""Exports: meshes, ParaView time series, control nets, reports, atomic writing."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from splinedeform import BSplineBasis, InputError, Surface
from splinedeform import export

meshio = pytest.importorskip("meshio")


def make_surface() -> Surface:
    """A curved open × uniform patch on [0, 1] × [0, 2] (no symmetry to hide index errors)."""
    bu, bv = BSplineBasis(3, 4, 1.0, "open"), BSplineBasis(2, 3, 2.0, "uniform")
    gu, gv = np.meshgrid(np.linspace(0, 1, bu.size), np.linspace(0, 2, bv.size), indexing="ij")
    P = np.stack([gu, gv + 0.1 * gu, 0.3 * np.sin(2 * gu) * np.cos(gv)], axis=-1)
    return Surface(P, bu, bv, name="test patch")


def make_motion(surface: Surface, frames: int = 4) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)
    times = np.linspace(0.0, 0.3, frames)
    shape = rng.normal(size=surface.control_points.shape)
    nets = surface.control_points[None] + np.sin(5 * times)[:, None, None, None] * shape[None]
    return times, nets


def grid_points(surface: Surface, net: np.ndarray, r: int) -> np.ndarray:
    """Surface points on the tessellation grid by pointwise evaluation (independent path)."""
    u = np.linspace(0, surface.basis_u.length, r)
    v = np.linspace(0, surface.basis_v.length, r)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    return surface.with_control_points(net).evaluate(uu, vv).reshape(-1, 3)


def hidden_files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


# -- tessellation of frames -------------------------------------------------------------
def test_tessellate_frames_matches_pointwise_evaluation():
    s = make_surface()
    _, nets = make_motion(s)
    X, faces = export.tessellate_frames(s, nets, 9)
    assert X.shape == (4, 81, 3)
    for f in range(4):
        np.testing.assert_allclose(X[f], grid_points(s, nets[f], 9), atol=1e-13)
        V, Fc = s.tessellate(9, control_points=nets[f])
        np.testing.assert_array_equal(faces, Fc)


def test_tessellate_frames_rejects_bad_resolution_and_shape():
    s = make_surface()
    with pytest.raises(InputError, match="resolution"):
        export.tessellate_frames(s, s.control_points, 1)
    with pytest.raises(InputError, match="resolution"):
        export.tessellate_frames(s, s.control_points, 2.5)
    with pytest.raises(InputError, match="shape"):
        export.tessellate_frames(s, np.zeros((3, 3, 3)), 8)


# -- meshes ---------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".obj", ".ply", ".vtu", ".vtk"])
def test_write_mesh_round_trip(tmp_path, suffix):
    s = make_surface()
    V, F = s.tessellate(7)
    disp = np.column_stack([V[:, 1], -V[:, 0], V[:, 2] ** 2])
    path = export.write_mesh(tmp_path / f"m{suffix}", V, F,
                             {"displacement": disp, "displacement_magnitude": V[:, 0]})
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points, V)
    np.testing.assert_array_equal(mesh.cells_dict["triangle"], F)
    if suffix in (".vtu", ".vtk"):
        np.testing.assert_array_equal(mesh.point_data["displacement"], disp)
        np.testing.assert_array_equal(mesh.point_data["displacement_magnitude"], V[:, 0])
    elif suffix == ".ply":
        for c in range(3):
            np.testing.assert_array_equal(mesh.point_data[f"displacement_{c}"], disp[:, c])
    assert hidden_files(tmp_path) == []


def test_write_mesh_stl_keeps_triangles_in_float32(tmp_path):
    s = make_surface()
    V, F = s.tessellate(6)
    mesh = meshio.read(export.write_mesh(tmp_path / "m.stl", V, F))
    got = mesh.points[mesh.cells_dict["triangle"]]            # (M, 3 corners, 3)
    want = V.astype(np.float32).astype(float)[F]
    # STL has no shared vertices: compare the triangle sets, independent of point order
    key = lambda t: np.array(sorted(map(tuple, t.reshape(-1, 9))))  # noqa: E731
    np.testing.assert_array_equal(key(got), key(want))


@pytest.mark.parametrize("vertices, faces, data, message", [
    (np.zeros((3, 2)), [[0, 1, 2]], None, "vertices"),
    ([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], None, "non-finite"),
    (np.eye(3), [[0, 1, 3]], None, "face indices"),
    (np.eye(3), [[0.0, 1.0, 2.0]], None, "integer"),
    (np.eye(3), [[0, 1, 2]], {"d": np.zeros(4)}, "point data"),
])
def test_write_mesh_rejects_bad_input(tmp_path, vertices, faces, data, message):
    with pytest.raises(InputError, match=message):
        export.write_mesh(tmp_path / "m.vtu", vertices, faces, data)
    assert list(tmp_path.iterdir()) == []


def test_write_mesh_rejects_unknown_suffix_and_missing_folder(tmp_path):
    with pytest.raises(InputError, match=r"\.obj"):
        export.write_mesh(tmp_path / "m.dxf", np.eye(3), [[0, 1, 2]])
    with pytest.raises(InputError, match="does not exist"):
        export.write_mesh(tmp_path / "nowhere" / "m.obj", np.eye(3), [[0, 1, 2]])


# -- ParaView time series ------------------------------------------------------------------------
def test_time_series_lists_every_frame_with_its_time_and_displacement(tmp_path):
    s = make_surface()
    times, nets = make_motion(s, 5)
    rest = s.control_points
    pvd = export.write_time_series(tmp_path, "motion", s, rest, times, nets, resolution=6)
    assert pvd == tmp_path / "motion.pvd"
    root = ET.parse(pvd).getroot()
    assert root.get("type") == "Collection"
    datasets = root.find("Collection").findall("DataSet")
    assert [float(d.get("timestep")) for d in datasets] == times.tolist()
    assert len({d.get("file") for d in datasets}) == 5
    X0 = grid_points(s, rest, 6)
    for f, d in enumerate(datasets):
        mesh = meshio.read(tmp_path / d.get("file"))
        X = grid_points(s, nets[f], 6)
        # points are the rest geometry; rest + displacement is the deformed surface
        np.testing.assert_allclose(mesh.points, X0, atol=1e-13)
        np.testing.assert_allclose(mesh.points + mesh.point_data["displacement"], X, atol=1e-13)
        np.testing.assert_allclose(mesh.point_data["displacement_magnitude"],
                                   np.linalg.norm(X - X0, axis=1), atol=1e-13)
    assert hidden_files(tmp_path) == []


def test_time_series_creates_its_folder_and_names_one_it_cannot_create(tmp_path):
    s = make_surface()
    times, nets = make_motion(s, 3)
    pvd = export.write_time_series(tmp_path / "new" / "series", "m", s, s.control_points,
                                   times, nets, resolution=4)
    assert pvd == tmp_path / "new" / "series" / "m.pvd" and pvd.is_file()
    assert sorted(p.name for p in pvd.parent.iterdir()) == [
        "m.pvd", "m_0000.vtu", "m_0001.vtu", "m_0002.vtu"]
    (tmp_path / "file").write_text("not a folder")
    with pytest.raises(InputError, match=r"cannot create the output folder .*file"):
        export.write_time_series(tmp_path / "file" / "series", "m", s, s.control_points,
                                 times, nets, resolution=4)


def test_time_series_rejects_mismatched_frames(tmp_path):
    s = make_surface()
    times, nets = make_motion(s, 3)
    with pytest.raises(InputError, match="nets must have shape"):
        export.write_time_series(tmp_path, "m", s, s.control_points, times[:2], nets)
    with pytest.raises(InputError, match="non-decreasing"):
        export.write_time_series(tmp_path, "m", s, s.control_points, times[::-1], nets)
    with pytest.raises(InputError, match="rest net"):
        export.write_time_series(tmp_path, "m", s, s.control_points[:-1], times, nets)
    with pytest.raises(InputError, match="stem"):
        export.write_time_series(tmp_path, "a/b", s, s.control_points, times, nets)
    with pytest.raises(InputError, match="non-decreasing"):         # checked before creating
        export.write_time_series(tmp_path / "new", "m", s, s.control_points, times[::-1], nets)
    assert list(tmp_path.iterdir()) == []


# -- control nets ------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".json", ".npz"])
def test_control_nets_round_trip_exactly(tmp_path, suffix):
    s = make_surface()
    times, nets = make_motion(s, 4)
    paths = export.write_control_nets(tmp_path, "nets", s, times, nets)
    assert [p.name for p in paths] == ["nets.json", "nets.npz"]
    path = tmp_path / f"nets{suffix}"
    uv = (np.array([0.0, 0.37, 1.0]), np.array([0.0, 1.21, 2.0]))
    for frame in (0, 2, -1):
        back = export.read_control_net(path, frame)
        np.testing.assert_array_equal(back.control_points, nets[frame])
        assert back.basis_u == s.basis_u and back.basis_v == s.basis_v
        assert back.name == "test patch"
        np.testing.assert_array_equal(back.evaluate(*uv),
                                      s.with_control_points(nets[frame]).evaluate(*uv))
    assert export.read_control_net(path).control_points.tolist() == nets[-1].tolist()


def test_control_net_json_describes_bases_and_times(tmp_path):
    s = make_surface()
    times, nets = make_motion(s, 3)
    export.write_control_nets(tmp_path, "nets", s, times, nets)
    doc = json.loads((tmp_path / "nets.json").read_text())
    short = {d: {k: doc["basis"][d][k] for k in ("degree", "cells", "length", "kind")}
             for d in "uv"}
    assert short == {"u": {"degree": 3, "cells": 4, "length": 1.0, "kind": "open"},
                     "v": {"degree": 2, "cells": 3, "length": 2.0, "kind": "uniform"}}
    # open: n zeros, the m + 1 breaks, n ends; uniform: the breaks extended by n cells
    assert doc["basis"]["u"]["knots"] == [0.0] * 3 + [0.0, 0.25, 0.5, 0.75, 1.0] + [1.0] * 3
    np.testing.assert_allclose(doc["basis"]["v"]["knots"], np.arange(-2, 6) * 2 / 3,
                               rtol=0, atol=1e-15)
    assert doc["domain"] == [[0.0, 1.0], [0.0, 2.0]] and doc["version"] == 2
    assert doc["times"] == times.tolist() and doc["shape"] == [7, 5]


def test_read_control_net_accepts_a_single_hand_written_net(tmp_path):
    s = make_surface()
    doc = {"basis": {"u": {"degree": 3, "cells": 4, "length": 1.0, "kind": "open"},
                     "v": {"degree": 2, "cells": 3, "length": 2.0, "kind": "uniform"}},
           "control_points": s.control_points.tolist()}
    (tmp_path / "one.json").write_text(json.dumps(doc))
    back = export.read_control_net(tmp_path / "one.json")
    np.testing.assert_array_equal(back.control_points, s.control_points)


def test_read_control_net_rejects_bad_files(tmp_path):
    s = make_surface()
    times, nets = make_motion(s, 2)
    export.write_control_nets(tmp_path, "nets", s, times, nets)
    with pytest.raises(InputError, match="frame"):
        export.read_control_net(tmp_path / "nets.json", 2)
    with pytest.raises(InputError, match="frame"):
        export.read_control_net(tmp_path / "nets.npz", -3)
    with pytest.raises(InputError, match="does not exist"):
        export.read_control_net(tmp_path / "missing.json")
    with pytest.raises(InputError, match=".json or .npz"):
        export.read_control_net(tmp_path / "nets.txt")
    (tmp_path / "broken.json").write_text("{not json")
    with pytest.raises(InputError, match="not a valid JSON"):
        export.read_control_net(tmp_path / "broken.json")
    (tmp_path / "partial.json").write_text(json.dumps({"control_points": []}))
    with pytest.raises(InputError, match="basis"):
        export.read_control_net(tmp_path / "partial.json")
    doc = json.loads((tmp_path / "nets.json").read_text())
    doc["basis"]["u"]["cells"] = 5           # net no longer fits the basis
    (tmp_path / "wrong.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match="shape"):
        export.read_control_net(tmp_path / "wrong.json")


# -- atomic writing ------------------------------------------------------------------------------
def test_interrupted_write_leaves_no_partial_target(tmp_path):
    def half_then_fail(tmp: Path) -> None:
        tmp.write_text("half of the content")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        export.write_with(tmp_path / "out.json", half_then_fail)
    assert list(tmp_path.iterdir()) == []


def test_interrupted_write_keeps_the_previous_file(tmp_path, monkeypatch):
    s = make_surface()
    V, F = s.tessellate(5)
    target = export.write_mesh(tmp_path / "m.vtu", V, F)
    before = target.read_bytes()

    def fail(path, mesh, **kwargs):
        Path(path).write_bytes(b"<VTKFile partial")
        raise OSError("interrupted")

    monkeypatch.setattr(meshio, "write", fail)
    with pytest.raises(OSError, match="interrupted"):
        export.write_mesh(target, 2 * V, F)
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["m.vtu"]


# -- reports ------------------------------------------------------------------------------------
def make_report() -> dict:
    return {
        "inputs": {"scenario": Path("demo.toml"), "net": np.array([7, 5]),
                   "material": {"mass": 1.5, "w20": np.float64(0.0125)}, "t_off": float("inf")},
        "solver": {"method": "analytic", "modes": np.int64(35)},
        "timings": {"assembly": 0.0123456789, "solve": np.float32(0.5)},
        "energies": {"time": np.linspace(0, 1, 101), "kinetic": np.linspace(0, 2, 101) ** 2},
        "probes": {"centre": {"u": 0.5, "v": 0.5, "max_displacement": 0.0734219},
                   "corner": {"u": 0.0, "v": 1.0, "max_displacement": 0.0}},
    }


def test_report_json_converts_numpy_values(tmp_path):
    json_path, md_path = export.write_report(tmp_path, make_report())
    assert (json_path.name, md_path.name) == ("report.json", "report.md")
    doc = json.loads(json_path.read_text())
    assert doc["inputs"]["net"] == [7, 5] and doc["inputs"]["scenario"] == "demo.toml"
    assert doc["inputs"]["t_off"] == "inf"
    assert doc["solver"]["modes"] == 35 and doc["timings"]["solve"] == 0.5
    assert doc["energies"]["kinetic"] == (np.linspace(0, 2, 101) ** 2).tolist()
    assert hidden_files(tmp_path) == []


def test_report_markdown_holds_the_numbers(tmp_path):
    _, md_path = export.write_report(tmp_path, make_report())
    text = md_path.read_text()
    for heading in ("## Inputs", "## Solver", "## Timings", "## Energies", "## Probes"):
        assert heading in text
    assert "| material.w20 | 0.0125 |" in text
    assert "| timings" not in text and "| assembly | 0.0123457 |" in text
    assert "| centre | 0.5 | 0.5 | 0.0734219 |" in text
    assert "|  | u | v | max_displacement |" in text
    # a long time table is thinned but keeps its first and last rows
    assert "| 0 | 0 |" in text and "| 1 | 4 |" in text
    assert "41 of 101 rows shown" in text


def test_report_rejects_unknown_values(tmp_path):
    with pytest.raises(InputError, match="report values"):
        export.write_report(tmp_path, {"solver": {"callback": object()}})
    with pytest.raises(InputError, match="mapping"):
        export.write_report(tmp_path, [("solver", 1)])
    assert list(tmp_path.iterdir()) == []
