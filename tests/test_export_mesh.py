"""Welded, watertight meshes of closed and degenerate surfaces; OBJ with vertex normals.

Checks are independent of our writer: files are read back with meshio (and the OBJ's
``vn`` / ``f a//a`` lines by hand), then

* duplicate points: pairs closer than 1e-9 of the diameter (k-d tree) — must be none;
* degenerate triangles: area below 1e-12 of the diameter squared — none (the smallest
  real triangle here has area ~1e-4);
* edges: each undirected edge counted; closed surfaces have every edge in exactly two
  triangles, with opposite directions (consistent orientation); open ones have their
  boundary edges exactly on their rims.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from splinedeform import export, shapes
from splinedeform.pipeline import run
from splinedeform.scenario import parse_scenario

meshio = pytest.importorskip("meshio")

R = 17          # tessellation points per direction


def diameter(points: np.ndarray) -> float:
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def duplicate_points(points: np.ndarray) -> int:
    return len(cKDTree(points).query_pairs(1e-9 * diameter(points)))


def degenerate_triangles(points: np.ndarray, faces: np.ndarray) -> int:
    a, b, c = (points[faces[:, i]] for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    return int(np.sum(area < 1e-12 * diameter(points) ** 2))


def edge_counts(faces: np.ndarray) -> tuple[dict, dict]:
    """Undirected edge → number of triangles; directed edge → number of triangles."""
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    d_keys, d_counts = np.unique(directed, axis=0, return_counts=True)
    u_keys, u_counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    return dict(zip(map(tuple, u_keys), u_counts)), dict(zip(map(tuple, d_keys), d_counts))


def boundary_edges(faces: np.ndarray) -> list[tuple[int, int]]:
    undirected, _ = edge_counts(faces)
    return [e for e, n in undirected.items() if n == 1]


def assert_oriented_manifold(faces: np.ndarray) -> None:
    undirected, directed = edge_counts(faces)
    assert max(undirected.values()) <= 2
    assert max(directed.values()) == 1       # no edge twice in one direction: consistent


def welded(surface):
    X, faces = export.tessellate_frames(surface, surface.control_points, R)
    keep, faces = export.weld(X, faces)
    return X[keep], faces


def test_torus_is_watertight():
    points, faces = welded(shapes.torus(cells=(10, 6)))
    assert duplicate_points(points) == 0 and degenerate_triangles(points, faces) == 0
    undirected, _ = edge_counts(faces)
    assert set(undirected.values()) == {2}                  # closed: every edge twice
    assert_oriented_manifold(faces)
    assert len(points) == (R - 1) ** 2                      # both seams welded
    # Euler characteristic of a torus: V - E + F = 0
    assert len(points) - len(undirected) + len(faces) == 0


def test_half_sphere_has_one_pole_point_and_its_rim_as_only_boundary():
    surface = shapes.half_sphere(cells=(12, 5))
    points, faces = welded(surface)
    assert duplicate_points(points) == 0 and degenerate_triangles(points, faces) == 0
    assert_oriented_manifold(faces)
    assert len(points) == (R - 1) * (R - 1) + 1             # seam welded, pole one point
    rim = boundary_edges(faces)
    assert len(rim) == R - 1
    rim_points = points[np.unique(rim)]
    np.testing.assert_allclose(rim_points[:, 2], 0.0, atol=1e-12)   # the rim is z = 0
    # a disc: V - E + F = 1
    assert len(points) - len(edge_counts(faces)[0]) + len(faces) == 1


def test_cylinder_boundary_is_its_two_rims():
    points, faces = welded(shapes.cylinder(cells=(9, 4)))
    assert duplicate_points(points) == 0 and degenerate_triangles(points, faces) == 0
    assert_oriented_manifold(faces)
    rim = boundary_edges(faces)
    assert len(rim) == 2 * (R - 1)
    z = points[np.unique(rim), 2]
    assert set(np.round(z, 9)) == {0.0, 2.0}


def test_an_open_plane_is_left_as_it_is():
    points, faces = welded(shapes.plane(cells=(4, 4)))
    assert len(points) == R * R and len(faces) == 2 * (R - 1) ** 2


def test_weld_keeps_points_apart_that_separate_in_a_later_frame():
    surface = shapes.half_sphere(cells=(12, 5))
    P = surface.control_points
    opened = P.copy()
    opened[:, -1, 0] += 0.1 * np.cos(np.arange(P.shape[0]))   # the pole row spreads out
    X, faces = export.tessellate_frames(surface, np.stack([P, opened]), R)
    keep, new_faces = export.weld(X, faces)
    assert len(keep) == (R - 1) * R                           # only the seam is welded


SCENARIO = """\
[surface]
shape = "half_sphere"
cells = [12, 5]

[material]
mass = 1.0
damping = 0.5
w10 = 1.0
w01 = 1.0

[boundary]
v0 = "clamped"
v1 = "pole"

[[load]]
kind = "uniform"
force = [0.0, 0.0, -0.3]

[solve]
kind = "dynamic"
t_end = 1.0
frames = 3

[output]
formats = ["obj", "stl", "ply", "vtu"]
resolution = 17
"""


def read_obj(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices, normals and faces of an OBJ, parsed by hand (faces must be ``a//a``)."""
    v, vn, f = [], [], []
    for line in path.read_text().splitlines():
        kind, *rest = line.split()
        if kind == "v":
            v.append([float(x) for x in rest])
        elif kind == "vn":
            vn.append([float(x) for x in rest])
        elif kind == "f":
            pairs = [item.split("//") for item in rest]
            assert all(a == b for a, b in pairs)            # normal index = vertex index
            f.append([int(a) - 1 for a, _ in pairs])
    return np.array(v), np.array(vn), np.array(f)


def test_a_half_sphere_run_writes_welded_meshes_with_normals(tmp_path):
    run(parse_scenario(SCENARIO, source="dome.toml"), tmp_path)
    points, normals, faces = read_obj(tmp_path / "dome.obj")
    assert duplicate_points(points) == 0 and degenerate_triangles(points, faces) == 0
    assert_oriented_manifold(faces)
    assert len(boundary_edges(faces)) == R - 1
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)
    # outward on a dome that is still nearly a sphere: within ~10° of the radial direction
    radial = points / np.linalg.norm(points, axis=1, keepdims=True)
    assert np.min(np.sum(normals * radial, axis=1)) > 0.98
    ply = meshio.read(tmp_path / "dome.ply")
    assert duplicate_points(ply.points) == 0
    assert degenerate_triangles(ply.points, ply.cells_dict["triangle"]) == 0
    stl = meshio.read(tmp_path / "dome.stl")
    assert degenerate_triangles(stl.points, stl.cells_dict["triangle"]) == 0
    assert len(stl.cells_dict["triangle"]) == len(faces)
    for vtu in sorted(tmp_path.glob("dome_*.vtu")):
        mesh = meshio.read(vtu)
        assert duplicate_points(mesh.points) == 0
        assert degenerate_triangles(mesh.points, mesh.cells_dict["triangle"]) == 0
