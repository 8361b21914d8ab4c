"""Every mode of a body in every per-mode output (mode_outputs.py, export/modes.py,
export/body.py), read back by meshio, ParaView's ``pvpython`` and the body's net reader:

* a closed 2 × 2 × 2 box of six faces (rhino3dm, in inches; elevated to degree 2 with one
  knot into every span) and a sphere of two hemispheres that share their meridians and
  poles (plain surfaces of a ``.3dm``), each run as a plate under tension with
  ``solve.kind = "modes"`` and mode 3 animated;
* each mode's written nets are an eigenvector of the body's model (the Rayleigh quotient
  ``qᵀ K q / qᵀ M q = ω_k²`` of the free coordinates they hold);
* ParaView reads mode 3's series as one welded grid of every face whose displacement at a
  quarter period is the mode's net displacement evaluated on every face;
* the seams stay closed in every mode: points of different faces that coincide at rest
  coincide in the mode's deformed state to 1e-9 of its largest displacement, and the
  welded mode mesh is closed (every triangle edge on two triangles).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import textwrap
from math import pi
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
meshio = pytest.importorskip("meshio")

import body_patches  # noqa: E402

from splinedeform.export.body_nets import read_body_control_nets  # noqa: E402
from splinedeform.pipeline import run  # noqa: E402
from splinedeform.scenario import load_scenario  # noqa: E402

RESOLUTION = 6
FRAMES = 5                  # phases 0, 1/4, 1/2, 3/4, 1: frame 1 is the quarter period
SCENARIO = """[surface]
shape = "cad"
path = "{path}"
{refine}
[material]
w10 = 1.0
w01 = 1.0
w20 = 0.4
w02 = 0.4

[solve]
kind = "modes"
modes = 4
frames = {frames}

[output]
formats = {formats}
resolution = {resolution}
animate_modes = [1, 3]
"""


def run_modes(folder: Path, source: Path, formats: str, refine: str = "") -> object:
    """The modes scenario of ``source`` (a CAD file in ``folder``) run into ``folder/out``."""
    path = folder / f"{source.stem}.toml"
    path.write_text(SCENARIO.format(path=source.name, refine=refine, frames=FRAMES,
                                    formats=formats, resolution=RESOLUTION))
    return run(load_scenario(path), folder / "out")


@pytest.fixture(scope="module")
def box(tmp_path_factory):
    folder = tmp_path_factory.mktemp("boxmodes")
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = r3.UnitSystem.Inches
    model.Objects.AddBrep(r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, 2, 2, 2))))
    assert model.Write(str(folder / "box.3dm"), 7)
    result = run_modes(folder, folder / "box.3dm",
                       '["vtu", "json", "npz", "images", "gif", "report"]',
                       "elevate = 1\nrefine = 1\n")
    return result, folder / "out"


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    from splinedeform.export.body import write_body_3dm

    folder = tmp_path_factory.mktemp("spheremodes")
    halves = [body_patches.hemisphere(2.0, start, cells=4) for start in (0.0, pi)]
    write_body_3dm(folder / "sphere.3dm", halves, [h.control_points for h in halves],
                   units="m")
    return run_modes(folder, folder / "sphere.3dm", '["vtu", "json"]'), folder / "out"


def test_every_mode_of_the_box_is_written(box):
    result, out = box
    names = {p.name for p in out.iterdir()}
    assert {f"box_mode{k}_nets.{ext}" for k in range(1, 5) for ext in ("json", "npz")} <= names
    assert {"box_modes.vtu", "box_mode3.pvd", "box_mode3.gif", "modes.png"} <= names
    assert {f"box_mode3_{f:04d}.vtu" for f in range(FRAMES)} <= names
    assert "box_mode2.pvd" not in names and "box_mode1.pvd" not in names   # not animated
    report = json.loads((out / "report.json").read_text())
    assert report["modes"]["mode"] == [1, 2, 3, 4]
    np.testing.assert_allclose(report["modes"]["omega"], result.omegas, rtol=1e-15)
    assert report["body"]["reversed"] == [False] * 6
    modes = meshio.read(out / "box_modes.vtu")
    assert {f"mode_{k}" for k in range(1, 5)} <= set(modes.point_data)
    assert set(np.unique(modes.point_data["patch"])) == set(range(6))


def free_coordinates(model, phi: list[np.ndarray]) -> np.ndarray:
    """The free coordinates ``q`` whose constrained field ``T q`` is ``phi`` (one scalar
    net per patch), checked to lie in the constrained space."""
    full = np.concatenate([p.ravel() for p in phi])
    T = model.constraints.T.toarray()
    q = np.linalg.lstsq(T, full, rcond=None)[0]
    # merged control points carry one value: T q reproduces the field to round-off
    assert np.abs(T @ q - full).max() <= 1e-10 * np.abs(full).max()
    return q


@pytest.mark.parametrize("k", [2, 3, 4])
def test_each_written_mode_is_an_eigenvector_of_the_body(box, k):
    from splinedeform.pipeline_body import body_net_normals

    result, out = box
    patches = list(result.built.surface.patches)
    normals = body_net_normals(patches)
    rests = [s.control_points for s in patches]
    # the quarter period of mode k's nets (sin(2π/4) = 1): P_rest + D_k, every face
    written = read_body_control_nets(out / f"box_mode{k}_nets.json", frame=1)
    assert sorted(written) == [0, 1, 2, 3, 4, 5]
    D = [written[f].control_points - r for f, r in zip(range(6), rests)]
    # a scalar mode moves along the unit n̄: its value is D · n̄, and D has no other part
    phi = [np.einsum("abc,abc->ab", d, n) for d, n in zip(D, normals)]
    for d, p, n in zip(D, phi, normals):
        np.testing.assert_allclose(d, p[..., None] * n, rtol=0, atol=1e-12)
    q = free_coordinates(result.built.model, phi)
    M, _, K = result.built.model.matrices()
    # Rayleigh quotient of an eigenvector from the sparse eigensolver: 1e-8 relative
    assert (q @ (K @ q)) / (q @ (M @ q)) == pytest.approx(result.omegas[k - 1] ** 2, rel=1e-8)


def sampled_mode(result, k: int, r: int) -> tuple[np.ndarray, np.ndarray]:
    """Every face's ``r × r`` grid points at rest and mode ``k``'s net displacement ``D_k``
    evaluated there (``Surface.evaluate``), face after face: ``(points, displacement)``."""
    points, moved = [], []
    for surface, D in zip(result.built.surface.patches, result.mode_nets):
        u, v = surface.sample_parameters(r)
        U, V = np.meshgrid(u, v, indexing="ij")
        points.append(surface.evaluate(U, V).reshape(-1, 3))
        moved.append(surface.with_control_points(D[k - 1]).evaluate(U, V).reshape(-1, 3))
    return np.concatenate(points), np.concatenate(moved)


PARAVIEW = textwrap.dedent("""
    import json, sys
    from paraview import servermanager
    from paraview.simple import PVDReader
    from vtk.util.numpy_support import vtk_to_numpy

    reader = PVDReader(FileName=sys.argv[1])
    times = list(reader.TimestepValues)
    reader.UpdatePipeline(times[1])
    data = servermanager.Fetch(reader)
    blocks = data.GetNumberOfBlocks() if data.IsA("vtkMultiBlockDataSet") else 1
    grid = data.GetBlock(0) if data.IsA("vtkMultiBlockDataSet") else data
    json.dump({"times": times, "blocks": blocks, "cells": grid.GetNumberOfCells(),
               "points": vtk_to_numpy(grid.GetPoints().GetData()).tolist(),
               "displacement": vtk_to_numpy(grid.GetPointData().GetArray("displacement")
                                            ).tolist()}, open(sys.argv[2], "w"))
""")


def test_paraview_reads_mode_3_of_every_face(box, tmp_path):
    pvpython = shutil.which("pvpython")
    if pvpython is None:
        pytest.skip("ParaView's pvpython is not installed (Debian package 'paraview')")
    result, out = box
    (tmp_path / "read.py").write_text(PARAVIEW)
    subprocess.run([pvpython, str(tmp_path / "read.py"), str(out / "box_mode3.pvd"),
                    str(tmp_path / "seen.json")], check=True, capture_output=True, timeout=300)
    seen = json.loads((tmp_path / "seen.json").read_text())
    assert seen["times"] == pytest.approx(np.linspace(0, 1, FRAMES).tolist(), abs=1e-15)
    r = RESOLUTION
    # one welded grid: the box's 6 r² grid points less the 12 edges' and 8 corners' repeats
    assert seen["blocks"] == 1 and len(seen["points"]) == 6 * r ** 2 - 12 * r + 8
    assert seen["cells"] == 12 * (r - 1) ** 2
    # at the quarter period the displacement is D_3 evaluated on each face's grid (every
    # face's sample at the point; the points are the rest geometry): 1e-12 of the size
    points, moved = sampled_mode(result, 3, r)
    tree = cKDTree(points)
    for at, d in zip(np.asarray(seen["points"]), np.asarray(seen["displacement"])):
        near = tree.query_ball_point(at, 1e-9)
        assert near, f"{at} is not a rest point of any face"
        np.testing.assert_allclose(moved[near], np.broadcast_to(d, (len(near), 3)),
                                   rtol=0, atol=2e-12)
    assert np.abs(seen["displacement"]).max() > 0.05          # the mode moves (0.2 = 10 %)


def closed_edges(triangles: np.ndarray) -> bool:
    """Whether every edge of the triangles is on exactly two of them."""
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                    triangles[:, [2, 0]]]), axis=1)
    _, count = np.unique(edges, axis=0, return_counts=True)
    return bool(np.all(count == 2))


@pytest.mark.parametrize("body", ["box", "sphere"])
def test_the_seams_stay_closed_in_every_mode(body, request):
    result, out = request.getfixturevalue(body)
    patches = list(result.built.surface.patches)
    size = float(np.ptp(np.concatenate([s.control_points.reshape(-1, 3) for s in patches]),
                        axis=0).max())
    for k in range(1, len(result.omegas) + 1):
        written = read_body_control_nets(out / f"{body}_mode{k}_nets.json", frame=1)
        rest, moved, owner = [], [], []
        for p, (face, surface) in enumerate(zip(sorted(written), patches)):
            u = np.linspace(0.0, surface.domain[0][1], 17)
            v = np.linspace(0.0, surface.domain[1][1], 17)
            U, V = np.meshgrid(u, v, indexing="ij")
            rest.append(surface.evaluate(U, V).reshape(-1, 3))
            moved.append(written[face].evaluate(U, V).reshape(-1, 3))
            owner.append(np.full(U.size, p))
        rest, moved, owner = map(np.concatenate, (rest, moved, owner))
        pairs = cKDTree(rest).query_pairs(1e-9 * size, output_type="ndarray")
        pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]          # across faces
        assert len(pairs) > 0
        largest = np.linalg.norm(moved - rest, axis=1).max()
        gap = np.linalg.norm(moved[pairs[:, 0]] - moved[pairs[:, 1]], axis=1).max()
        # merged control points, one normal: the faces meet to round-off
        assert gap <= 1e-9 * largest, f"mode {k}: gap {gap:.3g} at |d| {largest:.3g}"
    mesh = meshio.read(out / f"{body}_modes.vtu")
    assert closed_edges(mesh.cells_dict["triangle"])


def test_the_sphere_is_one_welded_grid_in_every_mode(sphere):
    _, out = sphere
    r = RESOLUTION
    # 2 (r - 1) meridians of r - 2 inner points each, and the two poles
    for name in ("sphere_modes.vtu", "sphere_mode3_0001.vtu"):
        assert len(meshio.read(out / name).points) == 2 * (r - 1) * (r - 2) + 2


@pytest.fixture(scope="module")
def shell_box(box, tmp_path_factory):
    """The box of :func:`box` as a Kirchhoff–Love shell, 7 modes (the six rigid motions
    and the lowest vibration), the seventh animated."""
    folder = tmp_path_factory.mktemp("shellmodes")
    shutil.copy(box[1].parent / "box.3dm", folder / "box.3dm")
    (folder / "shell.toml").write_text(
        '[surface]\nshape = "cad"\npath = "box.3dm"\nelevate = 1\nrefine = 1\n\n'
        '[material]\nphysics = "shell"\nE = 2.0e11\nnu = 0.3\nthickness = 0.01\n\n'
        f'[solve]\nkind = "modes"\nmodes = 7\nframes = {FRAMES}\n\n'
        f'[output]\nformats = ["vtu", "report"]\nresolution = {RESOLUTION - 1}\n'
        'animate_modes = [7]\n')
    return run(load_scenario(folder / "shell.toml"), folder / "out"), folder / "out"


def test_a_shell_body_s_mode_series_and_report_hold_every_face_s_stresses(shell_box):
    from splinedeform.outputs_body_shell import face_shells

    result, out = shell_box
    r, k = RESOLUTION - 1, 7
    report = json.loads((out / "report.json").read_text())
    top = report["modes"]["max von Mises top (mass-normalised shape)"]
    assert len(top) == len(report["modes"]["omega"]) == 7
    seen = meshio.read(out / "shell_mode7_0001.vtu")          # the quarter period
    assert len(seen.points) == 6 * r ** 2 - 12 * r + 8
    # mode 7 as written is c times its mass-normalised shape
    c = max(np.abs(D[k - 1]).max() for D in result.mode_nets) / \
        max(np.abs(S[k - 1]).max() for S in result.shell_modes)
    # each face's own von Mises (top) of D_7 on its grid, computed here face by face
    rest, stress, owner = [], [], []
    for p, (face, D) in enumerate(zip(face_shells(result.built.model), result.mode_nets)):
        u, v = face.surface.sample_parameters(r)
        U, V = np.meshgrid(u, v, indexing="ij")
        rest.append(face.surface.evaluate(U, V).reshape(-1, 3))
        stress.append(face.stresses(D[k - 1], U, V, at_poles="nan").von_mises["top"].ravel())
        owner.append(np.full(U.size, p))
    rest, stress, owner = map(np.concatenate, (rest, stress, owner))
    # the report's maximum is over every face (mass-normalised: divided by c); the
    # series' point takes the stress of the face it was first sampled on (`patch`);
    # both to round-off, 1e-9 of the largest stress
    peak = float(np.nanmax(stress))
    assert c * top[k - 1] == pytest.approx(peak, rel=1e-9)
    tree = cKDTree(rest)
    for at, p, s in zip(seen.points, seen.point_data["patch"], seen.point_data["von_mises_top"]):
        mine = [i for i in tree.query_ball_point(at, 1e-9) if abs(owner[i] - p) < 0.5]
        assert len(mine) == 1 and abs(stress[mine[0]] - s) <= 1e-9 * peak
