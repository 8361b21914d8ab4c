"""Fixed control points of a shell body: ``ShellModel(body, ..., fixed=[mask or None, ...])``
(physics/shell_body.py ``body_system``, body/constraints.py ``body_fixed_mask`` with
``components``) and the scenario key ``boundary.faces_free_points`` under
``physics = "shell"`` (scenario/body.py).

The unit square split along ``u = 0.5`` into two conforming bicubic patches (the right one
reversed in u, tests/body_patches.py) spans the same discrete space as one patch whose
knots repeat ``0.5`` three times (a C0 line): the merged control points are the single
patch's coefficients in another order (left row ``i`` ↔ row ``i``, right row ``i`` ↔ row
``10 − i``), and the slopes are tied exactly across the interface of the body as across the
smooth C0 line of the single patch. Holding the same control points (or components) on
both, the two constrained spaces are the same; only their bases differ (the merge is a
permutation, the ties a null-space basis of each), so the static displacements agree to
round-off of the solve: measured 1.6e-14 to 2.7e-14 of the largest displacement
(``K_r`` has a condition number of about 1e4). 1e-10 relative is
generous and still catches a point held or freed wrongly (an O(1) change). Held
components are zero rows of ``T``: ``T d_free`` there is an empty sum, exactly 0; it is
compared to 1e-14 of the scale as a stated tolerance.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.errors import InputError, ScenarioError
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel

from body_patches import (N, ROWS, flat_patch, halves, halves_3dm, halves_scenario,
                          single_row, split_square)

SHELL = ShellMaterial(E=1.0e4, nu=0.3, thickness=0.05, density=1.0)
BENDING = sd.Uniform((0.0, 0.0, -1.0))
IN_PLANE = sd.Uniform((1.0, 0.5, 0.0))
SAME = 1e-10      # same discrete space, another basis of it (module docstring)
REST = 1e-14      # a zero row of T: exactly 0, stated as a tolerance of the scale




def solve_both(fixed: list[np.ndarray | None], single_fixed: np.ndarray, load: sd.Load
               ) -> tuple[ShellModel, list[np.ndarray], np.ndarray]:
    """The body with ``fixed`` and the single patch with ``single_fixed`` under ``load``:
    the body's model, its nets and the single patch's net (the last frame)."""
    body = ShellModel(sd.Body(halves()), SHELL, "free", fixed=fixed)
    single = ShellModel(split_square((2, 1), 3), SHELL, {}, fixed=single_fixed)
    assert body.n_free == single.n_free
    assert body.rigid.shape[1] == single.rigid.shape[1] == 0
    nets = [np.asarray(d) for d in body.static(load).net_displacement()]
    whole = np.asarray(single.static(load).net_displacement())
    return body, nets, whole


def assert_same(nets: list[np.ndarray], whole: np.ndarray) -> float:
    """Each half's net against the single patch's rows (module docstring); the scale."""
    scale = float(np.abs(whole).max())
    assert scale > 0
    for p in range(2):
        rows = [single_row(p, i) for i in range(N)]
        np.testing.assert_allclose(nets[p], whole[rows], rtol=0, atol=SAME * scale)
    return scale


def edges_held() -> tuple[list[np.ndarray], np.ndarray]:
    """Whole points held on the square's sides x = 0 and x = 1 (row 0 of each half, rows
    0 and 10 of the single patch): a plate pinned on two opposite sides."""
    left, right = np.zeros((N, N), dtype=bool), np.zeros((N, N), dtype=bool)
    left[0], right[0] = True, True
    single = np.zeros((ROWS, N), dtype=bool)
    single[0], single[-1] = True, True
    return [left, right], single


def test_held_points_match_the_single_patch_and_are_at_rest():
    (left, right), single = edges_held()
    left[2, 3] = right[3, 1] = True               # an inner point of each half
    single[2, 3] = single[single_row(1, 3), 1] = True
    body, nets, whole = solve_both([left, right], single, BENDING)
    scale = assert_same(nets, whole)
    T = body.T.tocsr()
    for p, mask in enumerate((left, right)):
        offset = 3 * int(body.offsets[p])
        points = np.flatnonzero(mask.ravel())
        rows = offset + (3 * points[:, None] + np.arange(3)).ravel()
        assert T.getnnz(axis=1)[rows].max() == 0       # zero rows of T: counts, exact
        assert np.abs(nets[p][mask]).max() <= REST * scale
        # every other point moves: the least deflection of a free point is 2.6 % of the
        # largest (measured, next to a held point); 1e-3 of the scale leaves room
        assert np.abs(nets[p][~mask][:, 2]).min() > 1e-3 * scale


def test_a_point_on_the_interface_held_by_one_patch_is_held_in_both():
    (left, right), single = edges_held()
    left[5, 2] = True                              # row 5 of the left half: the interface
    single[5, 2] = True                            # the single patch's C0 line, row 5
    body, nets, whole = solve_both([left, right], single, BENDING)
    scale = assert_same(nets, whole)
    assert not right[5, 2]
    # the right half's own row 5 is the same point: held there too, a zero row of T
    assert np.abs(nets[1][5, 2]).max() <= REST * scale
    rows = 3 * (int(body.offsets[1]) + 5 * N + 2) + np.arange(3)
    assert body.T.tocsr().getnnz(axis=1)[rows].max() == 0
    # its neighbours on the interface move (measured 0.43 and 0.77 of the scale)
    assert abs(nets[1][5, 1, 2]) > 0.1 * scale and abs(nets[0][5, 3, 2]) > 0.1 * scale


def test_a_per_component_mask_holds_z_only():
    # the left side held whole, the right side (and one interface point, by the left
    # half) held in z only: no rigid motion is left, and under an in-plane load the
    # z-held points still move in x and y
    left, right = np.zeros((N, N, 3), dtype=bool), np.zeros((N, N, 3), dtype=bool)
    left[0] = True
    right[0, :, 2] = True
    left[5, 3, 2] = True
    single = np.zeros((ROWS, N, 3), dtype=bool)
    single[0], single[-1, :, 2], single[5, 3, 2] = True, True, True
    z_held = ((1, 0, 2), (0, 5, 3), (1, 5, 3))     # (patch, i, j): z held
    for load in (BENDING, IN_PLANE):
        body, nets, whole = solve_both([left, right], single, load)
        scale = assert_same(nets, whole)
        for p, i, j in z_held:
            assert abs(nets[p][i, j, 2]) <= REST * scale
    # under the in-plane load (the last) the z-held points move in the plane: at least
    # 51 % of the largest displacement (measured); 1e-3 of the scale leaves room
    for p, i, j in z_held:
        assert np.abs(nets[p][i, j, :2]).max() > 1e-3 * scale
    assert np.abs(nets[0][0]).max() <= REST * scale           # the side held whole
    x_free = body.T.tocsr().getnnz(axis=1)[3 * (int(body.offsets[1]) + 2) + np.arange(3)]
    assert x_free[:2].min() > 0 and x_free[2] == 0           # counts, exact


def test_a_curved_clamped_body_with_held_points_matches_the_single_patch():
    # both nets lifted to z = 0.3 y² (in the v direction the halves and the single patch
    # share: the same surface): its clamped sides are not in a coordinate plane, so their
    # rotation is Nitsche's (shell_clamp), which holds every rigid motion; the held
    # points are an inner one and one on the interface, held by the left half only
    from splinedeform.surface import Surface

    def bent(surface: sd.Surface) -> sd.Surface:
        net = surface.control_points.copy()
        net[..., 2] = 0.3 * net[..., 1] ** 2
        return Surface(net, surface.basis_u, surface.basis_v)

    left = np.zeros((N, N), dtype=bool)
    left[2, 3] = left[5, 2] = True
    single = np.zeros((ROWS, N), dtype=bool)
    single[2, 3] = single[5, 2] = True
    body = ShellModel(sd.Body([bent(s) for s in halves()]), SHELL, "clamped",
                      fixed=[left, None])
    one = ShellModel(bent(split_square((2, 1), 3)), SHELL,
                     {e: "clamped" for e in ("u0", "u1", "v0", "v1")}, fixed=single)
    assert body.n_free == one.n_free and body.rigid.shape[1] == 0
    nets = [np.asarray(d) for d in body.static(BENDING).net_displacement()]
    # the same space and the same clamp terms (the single patch's edge integrals split
    # at x = 0.5 on the same cells): measured 1.3e-14 of the scale apart
    scale = assert_same(nets, np.asarray(one.static(BENDING).net_displacement()))
    assert np.abs(nets[1][5, 2]).max() <= REST * scale


def test_a_pole_point_held_by_one_patch_holds_the_pole_of_both():
    # the sphere of two hemispheres sharing their poles (tests/body_patches.py), one
    # point of the south pole held by patch 0 only: the pole map ties it to the pole's
    # other points, the merge across the meridians to patch 1's pole, which is held
    # too; the three rotations about the held point stay free (an internal pressure does
    # no work on them), and the north pole, one point of both patches, rises by twice the
    # membrane solution w = p R²(1 − ν)/(2 E t)
    from math import pi

    from body_patches import hemisphere

    body = sd.Body([hemisphere(1.0, 0.0, 6), hemisphere(1.0, pi, 6)])
    mask = np.zeros(body.patches[0].shape, dtype=bool)
    mask[2, 0] = True                             # v0: the south pole's third point
    model = ShellModel(body, SHELL, "free", fixed=[mask, None])
    assert model.rigid.shape[1] == 3 and all(m.startswith("rotation")
                                             for m in model.rigid_motions)
    nets = [np.asarray(d) for d in model.static(sd.Pressure(1.0)).net_displacement()]
    scale = max(float(np.abs(n).max()) for n in nets)
    for net in nets:
        assert np.abs(net[:, 0]).max() <= REST * scale        # the south pole at rest
    # the north pole's points: one point (1e-12 of the scale: the pole maps' round-off)
    north = np.concatenate([nets[0][:, -1], nets[1][:, -1]])
    assert np.ptp(north, axis=0).max() <= 1e-12 * scale
    w = 1.0 * (1 - SHELL.nu) / (2 * SHELL.E * SHELL.thickness)
    # measured 0.47 % low (6 × 6 cells of an interpolated sphere); 1 % bounds it
    assert north[0, 2] == pytest.approx(2 * w, rel=1e-2)


@pytest.mark.parametrize("fixed, words", [
    ([np.zeros((N, N), dtype=bool)], "1 masks for a body of 2 patches"),
    ([None, np.zeros((N, N + 1), dtype=bool)],
     "fixed[1]: the mask of patch 1 must have the shape of its control net (n_u, n_v) = "
     "(6, 6) or, per component, (6, 6, 3)"),
    ([None, np.zeros((N, N, 2), dtype=bool)], "fixed[1]: the mask of patch 1 must have"),
    ([np.zeros((N, N)), None], "fixed[0]: the mask of patch 0 must be boolean"),
    ([np.zeros((N, N, 3), dtype=int), None], "fixed[0]: the mask of patch 0 must be boolean"),
    (np.zeros((2, N, N), dtype=bool), "a sequence of one mask"),
    ([np.ones((N, N), dtype=bool)] * 2, "no free displacement"),
])
def test_bad_masks_are_refused_naming_the_patch(fixed, words):
    with pytest.raises(InputError) as info:
        ShellModel(sd.Body(halves()), SHELL, "free", fixed=fixed)
    assert words in str(info.value)


def test_a_patch_held_whole_holds_its_neighbours_interface():
    # the left half held whole: the right one is clamped along the interface (its row 5
    # held, the slope tied to the left half's, which is at rest)
    body = ShellModel(sd.Body(halves()), SHELL, "free",
                      fixed=[np.ones((N, N), dtype=bool), None])
    nets = [np.asarray(d) for d in body.static(BENDING).net_displacement()]
    scale = float(np.abs(nets[1]).max())
    assert scale > 0 and np.abs(nets[0]).max() <= REST * scale
    assert np.abs(nets[1][5]).max() <= REST * scale
    # the slope across the interface is tied: row 4 moves by round-off of the tie's
    # null-space basis at most (measured 0; 1e-12 of the scale)
    assert np.abs(nets[1][4]).max() <= 1e-12 * scale


def test_an_untrimmed_patch_of_a_body_with_trimmed_faces_takes_held_points():
    # the left half untrimmed, the right one holed by a circle (coupled to it by the
    # iso-edge penalty, physics/shell_body_trimmed.py). Holding the left side's row 0
    # whole and row 1 in z is the flat plate's clamp of that side (open knots: the slope
    # at u = 0 is a multiple of d_1 − d_0, and a clamp in the plane z = 0 holds z's slope
    # only, physics/shell_edges.py), so the two maps hold the same coordinates and the
    # answers agree to round-off (measured 0; 1e-12 of the scale)
    from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain

    left = flat_patch((0, 0.5), (0, 1), (3, 3))
    outer = PolygonLoop([[0.0, 0.0], [0.5, 0.0], [0.5, 1.0], [0.0, 1.0]])
    right = flat_patch((0.5, 1), (0, 1), (3, 3)).with_trim(
        TrimDomain(outer, (CircleLoop((0.25, 0.5), 0.15),)))
    body = sd.Body([left, right])
    mask = np.zeros((N, N, 3), dtype=bool)
    mask[0], mask[1, :, 2] = True, True
    held = ShellModel(body, SHELL, "free", fixed=[mask, None])
    clamped = ShellModel(body, SHELL, {(0, "u0"): "clamped"})
    # the free rigid motions are counted on every point of the untrimmed patch, the
    # held ones at rest: none is left (counts, exact)
    assert held.rigid.shape[1] == clamped.rigid.shape[1] == 0
    assert held.n_free == clamped.n_free
    a = [np.asarray(d) for d in held.static(BENDING).net_displacement()]
    b = [np.asarray(d) for d in clamped.static(BENDING).net_displacement()]
    scale = max(float(np.abs(d).max()) for d in b)
    for x, y in zip(a, b):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * scale)
    # a pinned side leaves the rotation about it, and only that (before, the pinned
    # points of an untrimmed patch were left out and all six motions counted free)
    pinned = ShellModel(body, SHELL, {(0, "u0"): "pinned"})
    assert pinned.rigid_motions == ["rotation about the axis along (0, 1, 0) through "
                                    "(0, 0, 0)"]


# -- the scenario key boundary.faces_free_points under physics = "shell" -------------------
PATCH = "[[2, 2], [2, 3], [3, 2], [3, 3]]"


@pytest.fixture(scope="module")
def two_faces(tmp_path_factory):
    """The two halves as one Brep of two faces (face 0 the left half) in a ``.3dm``."""
    pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    return halves_3dm(tmp_path_factory.mktemp("shellfixed") / "two.3dm")


def shell_scenario(folder: Path, source: Path, boundary: str) -> Path:
    return halves_scenario(folder, source, "physics = \"shell\"\nE = 1.0e4\nnu = 0.3\n"
                           "thickness = 0.05\n", boundary)


def test_faces_free_points_of_a_shell_body_run_from_the_command_line(two_faces, tmp_path):
    from typer.testing import CliRunner

    from splinedeform import cli

    path = shell_scenario(tmp_path, two_faces, f"faces_free_points = {{0 = {PATCH}}}\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(cli.app, ["run", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["body"]["faces"] == [0, 1]
    nets = json.loads((out / "two_nets.json").read_text())["nets"]
    moved = [np.array(nets[k]["control_points"]) for k in ("0", "1")]
    motion = [np.abs(m[-1] - m[0]).max(axis=-1) for m in moved]
    scale = max(float(m.max()) for m in motion)
    assert scale > 0
    # face 0 moves at the four listed points only (the others are zero rows of T; the
    # nets are written as text: 1e-12 of the scale bounds the coordinates' round-trip)
    assert np.argwhere(motion[0] > 1e-12 * scale).tolist() == [[2, 2], [2, 3], [3, 2], [3, 3]]
    # face 1, not listed, as the model built directly with fixed = [mask, None]
    direct = ShellModel(sd.Body(halves()), SHELL, "free", fixed=[
        ~np.isin(np.arange(N * N).reshape(N, N), [2 * N + 2, 2 * N + 3, 3 * N + 2, 3 * N + 3]),
        None])
    d = [np.asarray(x) for x in direct.static(BENDING).net_displacement()]
    # the same body read back from the file: its nets are the written ones, so the answer
    # is the direct model's to round-off of the file's coordinates and the solve (1e-8
    # of the scale)
    for k in range(2):
        np.testing.assert_allclose(moved[k][-1] - moved[k][0], d[k], rtol=0,
                                   atol=1e-8 * scale)
    # face 1 is clamped along the interface: its row 5 held by face 0's mask, its row 4
    # by the slope tied to face 0's held rows 4 and 5 (1e-12: the tie's round-off); the
    # rest moves (at least 12 % of the scale, measured)
    assert motion[1][4:].max() <= 1e-12 * scale and motion[1][:4].min() > 1e-3 * scale


@pytest.mark.parametrize("boundary, where, words", [
    ("faces_free_points = {0 = [[2, 2], [6, 1]]}\n", "boundary.faces_free_points.0[2]",
     "[6, 1] is not a control point of face 0: its net has 6 x 6 points"),
    (f"faces_free_points = {{7 = {PATCH}}}\n", "boundary.faces_free_points.7",
     "face 7 is not in this body, whose faces are [0, 1]"),
    ("faces_free_points = {0 = []}\n", "boundary.faces_free_points.0", "is empty"),
])
def test_bad_faces_free_points_of_a_shell_body_name_the_key_path(two_faces, tmp_path,
                                                                boundary, where, words):
    from splinedeform.scenario import build, load_scenario

    path = shell_scenario(tmp_path, two_faces, boundary)
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(path))
    assert where in str(info.value) and words in str(info.value)
