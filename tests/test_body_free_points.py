"""Fixed control points of a body: ``BodyModel(..., fixed=...)`` (one mask per patch,
body/constraints.py ``body_fixed_mask``) and the scenario key
``boundary.faces_free_points`` (scenario/body.py ``face_masks``).

The unit square split along ``u = 0.5`` into two conforming bicubic patches (the right
one reversed in u, tests/body_patches.py) spans the same discrete space as one patch whose
knots repeat ``0.5`` three times (a C0 line): the merged control points are the single
patch's coefficients in another order (left ``i`` ↔ row ``i``, right ``i`` ↔ row
``10 − i``). Fixing the same control points on both sides, the reduced stiffness and load
are the same sums assembled in another order, so the static displacements agree to
round-off: the free sets here have 8 and 10 unknowns and ``K_r`` a condition number of
about 26 (measured: ``numpy.linalg.cond``), so the difference is ~1e-15 of the largest
displacement (measured 1e-15); 1e-10 relative is generous and still catches a wrong
point held or freed (an O(1) change). Fixed points are zero rows of ``T``: their displacement
``T d_free`` is an empty sum, exactly 0, which is why those are compared with atol 0.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.errors import InputError

from body_patches import (N, ROWS, halves, halves_3dm, halves_scenario, single_row,
                          split_square)

MEMBRANE = sd.Material(w10=1.0, w01=1.0)
LOAD = sd.Uniform((0.0, 0.0, -1.0))
SAME = 1e-10      # same discrete space, another assembly order (module docstring)




def masks(free: dict[int, list[tuple[int, int]]]) -> list[np.ndarray]:
    """Per half, every point fixed except those listed."""
    out = [np.ones((N, N), dtype=bool), np.ones((N, N), dtype=bool)]
    for p, points in free.items():
        for i, j in points:
            out[p][i, j] = False
    return out


def single_mask(free: set[tuple[int, int]]) -> np.ndarray:
    mask = np.ones((ROWS, N), dtype=bool)
    for i, j in free:
        mask[i, j] = False
    return mask


def compare(free: dict[int, list[tuple[int, int]]], moving: set[tuple[int, int]]) -> None:
    """Body with the masks of ``free`` against the single patch whose free set is
    ``moving``: same unknown count, same nets (held points exactly 0)."""
    body = sd.BodyModel(sd.Body(halves()), MEMBRANE, boundary="free", fixed=masks(free))
    single = sd.Model(split_square((2, 1), 3), MEMBRANE, boundary="free",
                      fixed=single_mask(moving), physics="intrinsic")
    assert body.n_free == single.n_free == len(moving)
    assert not body.constraints.unconstrained and body.rigid_modes == 0
    d_body = body.to_full(body.static(LOAD).d_free)
    d_single = single.to_full(single.static(LOAD).d_free)
    scale = np.abs(d_single).max()
    assert scale > 0
    for p in range(2):
        for i in range(N):
            row = single_row(p, i)
            for j in range(N):
                if (row, j) in moving:
                    np.testing.assert_allclose(d_body[p][i, j], d_single[row, j], rtol=0,
                                               atol=SAME * scale)
                    assert np.abs(d_body[p][i, j, 2]) > 1e-3 * scale   # it does move
                else:   # a zero row of T: 0 up to nothing but round-off of T d (none
                    # in exact zeros; 1e-14 of the scale states it as a tolerance)
                    assert np.abs(d_body[p][i, j]).max() <= 1e-14 * scale


def test_only_the_listed_points_move_and_match_the_single_patch() -> None:
    # rows 3..5 of the left half and 5..3 of the right one (its row 5 is the shared
    # interface row): the single patch's rows 3..7, columns 2 and 3
    cols = (2, 3)
    free = {0: [(i, j) for i in (3, 4, 5) for j in cols],
            1: [(i, j) for i in (5, 4, 3) for j in cols]}
    compare(free, {(r, j) for r in range(3, 8) for j in cols})


def test_a_shared_point_fixed_by_one_face_only_is_fixed() -> None:
    # the left half frees the interface row 5, the right half does not: it stays put
    cols = (2, 3)
    free = {0: [(i, j) for i in (3, 4, 5) for j in cols],
            1: [(i, j) for i in (4, 3) for j in cols]}
    compare(free, {(r, j) for r in (3, 4, 6, 7) for j in cols})


def test_a_face_without_a_mask_moves_apart_from_its_edges() -> None:
    # None for the right half: only the left half's mask holds; the interface row is
    # held by the left mask, so the right half moves wherever its edges let it
    left = np.ones((N, N), dtype=bool)
    left[2:4, 2:4] = False
    body = sd.BodyModel(sd.Body(halves()), MEMBRANE, boundary="clamped", fixed=[left, None])
    plain = sd.BodyModel(sd.Body(halves()), MEMBRANE, boundary="clamped")
    # clamped: the two rows or columns next to a boundary edge are fixed (columns 0, 1,
    # 4, 5; the right half's rows 0, 1 at x = 1); the right half keeps rows 2..4 (its u1
    # row 5 is the shared one the left mask holds) in columns 2, 3; the left half its 2 × 2
    assert body.n_free == 4 + 3 * 2
    assert plain.n_free > body.n_free
    assert body.constraints.fixed_patches == frozenset({0, 1})    # the shared row


@pytest.mark.parametrize("fixed, words", [
    ([np.zeros((N, N), dtype=bool)], "1 masks for a body of 2 patches"),
    ([None, np.zeros((N, N + 1), dtype=bool)], "fixed[1]: the mask of patch 1 must have the "
                                               "shape of its control net (n_u, n_v) = (6, 6)"),
    ([np.zeros((N, N)), None], "fixed[0]: the mask of patch 0 must be boolean"),
    (np.zeros((2, N, N), dtype=bool), "a sequence of one mask"),
    ([np.ones((N, N), dtype=bool)] * 2, "every control point is fixed"),
])
def test_bad_masks_are_refused_naming_the_patch(fixed, words) -> None:
    with pytest.raises(InputError) as info:
        sd.BodyModel(sd.Body(halves()), MEMBRANE, fixed=fixed)
    assert words in str(info.value)


# -- the scenario key boundary.faces_free_points ------------------------------------------
CLAMPED = 'u0 = "clamped"\nu1 = "clamped"\nv0 = "clamped"\nv1 = "clamped"\n'
PATCH = "[[2, 2], [2, 3], [3, 2], [3, 3]]"


@pytest.fixture(scope="module")
def two_faces(tmp_path_factory):
    """The two halves as one Brep of two faces (face 0 the left half) in a ``.3dm``."""
    pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    return halves_3dm(tmp_path_factory.mktemp("bodyfree") / "two.3dm")


def scenario_of(folder: Path, source: Path, boundary: str) -> Path:
    return halves_scenario(folder, source, "w10 = 1.0\nw01 = 1.0\n", boundary,
                           '"vtu", "json", "report"')


def test_faces_free_points_runs_and_moves_the_listed_points_only(two_faces, tmp_path):
    import json

    from typer.testing import CliRunner

    from splinedeform import cli
    from splinedeform.scenario import build, load_scenario, scenario_to_toml

    path = scenario_of(tmp_path, two_faces, CLAMPED + f"faces_free_points = {{0 = {PATCH}}}\n")
    scenario = load_scenario(path)
    built = build(scenario)
    assert built.surface.faces == (0, 1)
    # face 0 moves at the four listed points only; face 1, not listed, within its edges
    # (the body above with fixed = [mask, None])
    left = np.ones((N, N), dtype=bool)
    left[2:4, 2:4] = False
    direct = sd.BodyModel(sd.Body(halves()), MEMBRANE, boundary="clamped", fixed=[left, None])
    assert built.model.n_free == direct.n_free == 10
    d = built.model.to_full(built.model.static(LOAD).d_free)
    moving = np.argwhere(np.any(d[0] != 0.0, axis=-1))    # zero rows of T: exact zeros
    assert moving.tolist() == [[2, 2], [2, 3], [3, 2], [3, 3]]
    # the key is written back as read
    again = tmp_path / "again.toml"
    again.write_text(scenario_to_toml(scenario))
    assert load_scenario(again).raw["boundary"]["faces_free_points"] == {
        "0": [[2, 2], [2, 3], [3, 2], [3, 3]]}

    out = tmp_path / "out"
    result = CliRunner().invoke(cli.app, ["run", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["body"]["faces"] == [0, 1]
    assert (out / "two.pvd").exists() and (out / "two_nets.json").exists()
    nets = json.loads((out / "two_nets.json").read_text())
    assert set(nets["nets"]) == {"0", "1"}


@pytest.mark.parametrize("boundary, where, words", [
    (f"faces_free_points = {{0 = [[2, 2], [6, 1]]}}\n", "boundary.faces_free_points.0[2]",
     "[6, 1] is not a control point of face 0: its net has 6 x 6 points"),
    (f"faces_free_points = {{7 = {PATCH}}}\n", "boundary.faces_free_points.7",
     "face 7 is not in this body, whose faces are [0, 1]"),
    ("faces_free_points = {0 = []}\n", "boundary.faces_free_points.0", "is empty"),
    ("faces_free_points = {0 = [[2]]}\n", "boundary.faces_free_points", ""),
    (f"free_points = {PATCH}\n", "boundary.free_points", "boundary.faces_free_points"),
    ("free_region = {u = [0.1, 0.4]}\n", "boundary.free_region",
     "boundary.faces_free_points"),
])
def test_bad_faces_free_points_name_the_key_path(two_faces, tmp_path, boundary, where,
                                                 words):
    from splinedeform.errors import ScenarioError
    from splinedeform.scenario import build, load_scenario

    path = scenario_of(tmp_path, two_faces, CLAMPED + boundary)
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(path))
    assert where in str(info.value) and words in str(info.value)


def test_faces_free_points_is_refused_on_one_surface(tmp_path):
    from splinedeform.errors import ScenarioError
    from splinedeform.scenario import build, load_scenario

    path = tmp_path / "one.toml"
    path.write_text('[surface]\nshape = "plane"\ncells = 2\n[material]\nw10 = 1.0\n'
                    f'w01 = 1.0\n[boundary]\nfaces_free_points = {{0 = {PATCH}}}\n'
                    '[solve]\nkind = "modes"\n')
    with pytest.raises(ScenarioError, match="boundary.faces_free_points") as info:
        build(load_scenario(path))
    assert "boundary.free_points" in str(info.value)
