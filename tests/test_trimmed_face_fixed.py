"""Fixed control points on the trimmed faces of a body (plate and shell).

A trimmed face's mask is taken by its own map, Höllig's extension with the fixed points
left out of the free set (:func:`splinedeform.trim.holed.with_edges`), as a single trimmed
surface takes it: a held inner or outer B-spline's coefficient is at rest, a dead one (its
support outside the region) was at rest already.
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.errors import InputError, ScenarioError
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain
from splinedeform.trim.model_matrices import quadrature_of
from splinedeform.trim.surface_trim import surface_degrees
from splinedeform.trim.web import web_basis

PLATE = sd.Material(w10=1.0, w01=1.0, w20=0.01, w11=0.01, w02=0.01)
SHELL = ShellMaterial(E=1.0e4, nu=0.3, thickness=0.05)
LOAD = sd.Uniform((0.0, 0.0, 1.0))
CIRCLE = CircleLoop((0.5, 0.5), 0.3)
SQUARE = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def disc(cells: int = 10) -> sd.Surface:
    """The disc ``|x − (½, ½)| < 0.3`` trimmed from the cubic unit square (open knots)."""
    return sd.shapes.plane(cells=(cells,) * 2, degree=3, knots="open").with_trim(
        TrimDomain(CIRCLE))


def kinds(surface: sd.Surface) -> tuple[np.ndarray, np.ndarray]:
    """The inner and outer tables of the face's B-splines (independent of the mask)."""
    web = web_basis(quadrature_of(surface).classes, surface_degrees(surface))
    return web.inner, web.outer


def held_mask(surface: sd.Surface) -> np.ndarray:
    """Two inner points at the rim of the inner block, one outer point and one dead corner
    point: what a mask may hold (a point inside the 7 × 7 inner block of a 10-cell disc
    would leave no 4 × 4 free block to tie the outer B-splines to)."""
    inner, outer = kinds(surface)
    mask = np.zeros(surface.shape, dtype=bool)
    mask[3, 6] = mask[4, 3] = True            # inner (rows 3 … 9 are, at columns 3 … 9)
    mask[2, 4] = True                         # outer (row 2, columns 2 … 10)
    mask[0, 0] = True                         # dead
    assert inner[3, 6] and inner[4, 3] and outer[2, 4] and not (inner | outer)[0, 0]
    return mask


def zero_rows(T) -> np.ndarray:
    """Rows of a sparse map without a nonzero entry (counts of stored entries: exact)."""
    T = T.tocsr()
    return np.diff(T.indptr) == 0


# -- the plate --------------------------------------------------------------------------
def test_a_body_of_one_trimmed_face_is_the_single_surface_with_its_mask():
    face = disc()
    mask = held_mask(face)
    single = sd.Model(face, PLATE, fixed=mask, physics="parametric")
    body = sd.BodyModel(sd.Body([face]), PLATE, fixed=[mask], physics="parametric")
    assert body.n_free == single.n_free                      # counts: exact
    a = np.asarray(single.to_full(single.static(LOAD).d_free))
    b = np.asarray(body.to_full(body.static(LOAD).d_free)[0])
    scale = np.abs(a).max()
    # one space, one set of matrices assembled in two orders: the solves agree to
    # round-off (measured 1.6e-16 of the scale); 1e-10 leaves the condition number room
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-10 * scale)


def test_held_points_are_zero_rows_at_rest_and_free_ones_move():
    face = disc()
    mask = held_mask(face)
    inner, outer = kinds(face)
    model = sd.BodyModel(sd.Body([face]), PLATE, fixed=[mask], physics="parametric")
    T = model.constraints.T
    rows = zero_rows(T).reshape(face.shape)
    assert rows[mask].all()                       # every held point a zero row of T
    # without the mask the held inner and outer points move (nonzero rows), the dead one
    # does not: the mask is what holds them
    free = sd.BodyModel(sd.Body([face]), PLATE, physics="parametric")
    before = zero_rows(free.constraints.T).reshape(face.shape)
    assert not before[3, 6] and not before[4, 3] and not before[2, 4] and before[0, 0]
    d = np.abs(np.asarray(model.to_full(model.static(LOAD).d_free)[0])).max(axis=-1)
    scale = d.max()
    # zero rows: exact zeros; asserted to 1e-14 of the scale
    assert d[mask].max() <= 1e-14 * scale
    # every other inner point moves, by at least 1e-3 of the scale (measured 1.1 %
    # at the least, beside the held ones)
    moving = inner & ~mask
    assert d[moving].min() > 1e-3 * scale
    # the held face holds the body: no rigid mode left under tension (count, exact)
    assert model.rigid_modes == 0


def split_square(disc_cells: int = 8, ring_cells: int = 8) -> sd.Body:
    """The disc and the square less the disc, each a trimmed cubic unit square."""
    inside = sd.shapes.plane(cells=(disc_cells,) * 2, degree=3, knots="open")
    ring = sd.shapes.plane(cells=(ring_cells,) * 2, degree=3, knots="open")
    return sd.Body([inside.with_trim(TrimDomain(CIRCLE)),
                    ring.with_trim(TrimDomain(SQUARE, (CIRCLE,)))])


def test_two_faces_sharing_a_trim_curve_hold_a_point_in_the_face_that_holds_it():
    # the ring holds one outer point next to the circle (its B-spline meets the circle);
    # no control point of a trimmed face is merged with another face's (the curve is
    # coupled by penalties), so the ring's map holds it and the disc's map is unchanged
    body = split_square()
    ring = body.patches[1]
    inner, outer = kinds(ring)
    mask = np.zeros(ring.shape, dtype=bool)
    mask[4, 5] = True
    assert outer[4, 5]                        # on the circle's cut cells
    held = sd.BodyModel(body, PLATE, boundary="free", fixed=[None, mask],
                        physics="parametric")
    loose = sd.BodyModel(body, PLATE, boundary="free", physics="parametric")
    n0 = body.patches[0].shape[0] * body.patches[0].shape[1]
    T, T0 = held.constraints.T.tocsr(), loose.constraints.T.tocsr()
    assert held.n_free == loose.n_free        # an outer point is no unknown: counts exact
    assert zero_rows(T[n0:]).reshape(ring.shape)[4, 5]
    assert not zero_rows(T0[n0:]).reshape(ring.shape)[4, 5]
    # the disc's rows are the same map (0 or 1 entries, the same columns first)
    assert (zero_rows(T[:n0]) == zero_rows(T0[:n0])).all()
    assert held.constraints.fixed_patches == frozenset({1})
    # one face held holds the two, coupled along the circle: no rigid mode (count, exact)
    assert held.rigid_modes == 0 and loose.rigid_modes == 1
    d = [np.abs(np.asarray(x)).max(axis=-1) for x in held.to_full(held.static(LOAD).d_free)]
    scale = max(x.max() for x in d)
    assert d[1][4, 5] <= 1e-14 * scale        # a zero row: an exact zero
    # the ring's map is the single ring's with the same mask, block for block (the same
    # construction: 0/1 and extension entries, to 1e-14 of their size 1)
    alone = sd.Model(ring, PLATE, fixed=mask, physics="parametric").constraints.T
    ring_columns = np.flatnonzero(np.asarray(abs(T[n0:]).sum(axis=0)).ravel())
    np.testing.assert_allclose(T[n0:][:, ring_columns].toarray(), alone.toarray(),
                               rtol=0, atol=1e-14)


@pytest.mark.parametrize("fixed, words", [
    ([np.zeros((3, 3), dtype=bool)], "fixed[0]: the mask of patch 0 must have the shape"),
    ([np.zeros((13, 13), dtype=int)], "fixed[0]: the mask of patch 0 must be boolean"),
    ([np.ones((13, 13), dtype=bool)], "fixed[0]: face 0 is trimmed"),
])
def test_bad_masks_on_a_trimmed_face_are_refused_naming_it(fixed, words):
    with pytest.raises(InputError) as info:
        sd.BodyModel(sd.Body([disc()]), PLATE, fixed=fixed, physics="parametric")
    assert words in str(info.value)


def test_a_mask_that_leaves_no_free_block_names_the_face():
    # the centre of the 7 × 7 inner block: every 4 × 4 block of inner points holds it
    mask = np.zeros((13, 13), dtype=bool)
    mask[6, 6] = True
    with pytest.raises(InputError) as info:
        sd.BodyModel(sd.Body([disc()]), PLATE, fixed=[mask], physics="parametric")
    message = str(info.value)
    assert "fixed[0]: face 0 is trimmed" in message and "free more points" in message


def test_a_mask_of_dead_points_only_holds_nothing():
    # dead B-splines are at rest anyway: the body keeps its rigid mode and its unknowns
    mask = np.zeros((13, 13), dtype=bool)
    mask[0, :] = True
    held = sd.BodyModel(sd.Body([disc()]), PLATE, fixed=[mask], physics="parametric")
    free = sd.BodyModel(sd.Body([disc()]), PLATE, physics="parametric")
    assert held.n_free == free.n_free and held.rigid_modes == free.rigid_modes == 1
    # and so does the single surface (counts, exact)
    assert sd.Model(disc(), PLATE, fixed=mask, physics="parametric").rigid_modes == 1


# -- the shell --------------------------------------------------------------------------
def test_a_shell_body_of_one_trimmed_face_is_the_single_surface_with_its_mask():
    face = disc()
    mask = held_mask(face)
    single = ShellModel(face, SHELL, {"outer": "free"}, fixed=mask)
    body = ShellModel(sd.Body([face]), SHELL, "free", fixed=[mask])
    assert body.n_free == single.n_free                      # counts: exact
    a = np.asarray(single.static(LOAD).net_displacement())
    b = np.asarray(body.static(LOAD).net_displacement()[0])
    scale = np.abs(a).max()
    # the same space and matrices, assembled and solved by two paths: round-off apart
    # (measured 8.4e-13 of the scale, the thin shell's conditioning; 1e-10 leaves room)
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-10 * scale)
    # the held points are at rest (zero rows of T: exact; 1e-14 of the scale asserted)
    assert np.abs(b[mask]).max() <= 1e-14 * scale
    assert zero_rows(body.formulation.T[::3]).reshape(face.shape)[mask].all()
    # held points at rest fix the rigid motions: none left (counts, exact)
    assert body.rigid.shape[1] == single.rigid.shape[1] == 0


def test_one_held_point_of_a_trimmed_shell_leaves_the_rotations_about_it():
    # a rigid motion vanishing at one control point is a rotation about an axis through
    # it: three are left, counted on the moving points and the held one at rest (counts)
    face = disc()
    mask = np.zeros(face.shape, dtype=bool)
    mask[3, 6] = True
    body = ShellModel(sd.Body([face]), SHELL, "free", fixed=[mask])
    single = ShellModel(face, SHELL, {"outer": "free"}, fixed=mask)
    free = ShellModel(sd.Body([face]), SHELL, "free")
    assert body.rigid.shape[1] == single.rigid.shape[1] == 3
    assert free.rigid.shape[1] == 6


def test_a_per_component_mask_on_a_trimmed_shell_face_is_refused_unless_whole():
    face = disc()
    mask = np.zeros(face.shape + (3,), dtype=bool)
    mask[3, 6, 2] = True
    with pytest.raises(InputError) as info:
        ShellModel(sd.Body([face]), SHELL, "free", fixed=[mask])
    assert "fixed[0]: face 0 is trimmed" in str(info.value)
    assert "[3, 6] hold some components only" in str(info.value)
    mask[3, 6] = True                               # all three: taken as the whole point
    whole = ShellModel(sd.Body([face]), SHELL, "free", fixed=[mask])
    point = ShellModel(sd.Body([face]), SHELL, "free", fixed=[mask[..., 0]])
    assert whole.n_free == point.n_free == ShellModel(sd.Body([face]), SHELL).n_free - 3


# -- the scenario key boundary.faces_free_points ----------------------------------------
@pytest.fixture(scope="module")
def two_trimmed(tmp_path_factory):
    """The disc and the ring as one Brep of two trimmed faces in a ``.3dm``."""
    pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    from splinedeform.export.body import write_body_3dm

    body = split_square(10, 6)
    return write_body_3dm(tmp_path_factory.mktemp("trimfixed") / "two.3dm", list(body),
                          [s.control_points for s in body], body=body)


def scenario_of(folder, source, physics: str, free: str):
    import shutil

    shutil.copy(source, folder / source.name)
    material = ('physics = "shell"\nE = 1.0e4\nnu = 0.3\nthickness = 0.05\n'
                if physics == "shell" else
                'physics = "parametric"\nw10 = 1.0\nw01 = 1.0\n')
    path = folder / "two.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{source.name}"\n'
                    f'[material]\n{material}'
                    f'[boundary.faces_free_points]\n{free}\n'
                    '[[load]]\nkind = "uniform"\nforce = [0.0, 0.0, -1.0]\n'
                    '[solve]\nkind = "static"\n'
                    '[output]\nformats = ["json"]\nresolution = 5\n')
    return path


@pytest.mark.parametrize("physics", ["parametric", "shell"])
def test_faces_free_points_on_a_trimmed_face_holds_the_others(two_trimmed, tmp_path,
                                                              physics):
    from splinedeform.scenario import build, load_scenario

    # a 4 × 4 block of the disc's inner points: the outer ones, held, need none
    listed = [[i, j] for i in range(3, 7) for j in range(3, 7)]
    built = build(load_scenario(scenario_of(tmp_path, two_trimmed, physics,
                                            f"0 = {listed}")))
    body = built.surface
    face = body.patches[body.patch_of_face(0)]
    mask = np.ones(face.shape, dtype=bool)
    mask[tuple(np.array(listed).T)] = False
    fixed = [mask if p == body.patch_of_face(0) else None for p in range(len(body))]
    direct = (ShellModel(body, SHELL, "free", fixed=fixed) if physics == "shell" else
              sd.BodyModel(body, sd.Material(w10=1.0, w01=1.0), fixed=fixed,
                           physics="parametric"))
    assert built.model.n_free == direct.n_free                    # counts: exact
    T = built.model.constraints.T if physics != "shell" else built.model.formulation.T[::3]
    moving = ~zero_rows(T[:face.shape[0] * face.shape[1]]).reshape(face.shape)
    assert np.argwhere(moving).tolist() == listed


@pytest.mark.parametrize("physics", ["parametric", "shell"])
def test_a_trimmed_face_freed_too_little_is_refused_at_its_key(two_trimmed, tmp_path,
                                                               physics):
    from splinedeform.scenario import build, load_scenario

    path = scenario_of(tmp_path, two_trimmed, physics, "1 = [[0, 0]]")
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(path))
    message = str(info.value)
    assert "boundary.faces_free_points.1" in message and "free more points" in message
