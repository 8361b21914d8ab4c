"""A body of patches deformed as one model equals the single patch of the same space.

The unit square split into 2 or 4 conforming patches (one of them reversed) spans the
same discrete space as one patch whose knot vectors repeat the split lines ``degree``
times (C0 lines): its merged control points are the single patch's coefficients, in
another order. The energies, loads and constraints are the same integrals assembled in
another order, so static displacements, frequencies and motions agree to round-off:
1e-10 relative is generous for matrices of ~100 unknowns whose condition number is ~1e4.
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.body import Body, Interface, OnPatch

from body_patches import flat_patch, split_square

MEMBRANE = sd.Material(w10=1.0, w01=1.0)
LOAD = sd.Uniform((0.0, 0.0, -1.0))
SAME = 1e-10      # same discrete space, another assembly order (module docstring)


def halves() -> list[sd.Surface]:
    """The unit square as two patches, the right one reversed in u."""
    return [flat_patch((0, 0.5), (0, 1), (3, 3)),
            flat_patch((0.5, 1), (0, 1), (3, 3), reverse_u=True)]


def quarters() -> list[sd.Surface]:
    """Four patches; the top right one reversed in v (its interfaces run backwards)."""
    return [flat_patch((0, 0.5), (0, 0.5), (3, 3)), flat_patch((0.5, 1), (0, 0.5), (3, 3)),
            flat_patch((0, 0.5), (0.5, 1), (3, 3)),
            flat_patch((0.5, 1), (0.5, 1), (3, 3), reverse_v=True)]


def lifted(surface: sd.Surface) -> sd.Surface:
    """The net raised to ``z = x y (1 − y)`` at its control points."""
    net = np.array(surface.control_points)
    net[..., 2] = net[..., 0] * net[..., 1] * (1 - net[..., 1])
    return surface.with_control_points(net)


@pytest.mark.parametrize("boundary", ["clamped", "pinned"])
@pytest.mark.parametrize("split", [(2, 1), (2, 2)])
def test_split_membrane_equals_single_patch(boundary: str, split: tuple[int, int]) -> None:
    patches = halves() if split == (2, 1) else quarters()
    single = sd.Model(split_square(split, 3), MEMBRANE, boundary=boundary, physics="intrinsic")
    body = sd.BodyModel(sd.Body(patches), MEMBRANE, boundary=boundary)
    assert body.n_free == single.n_free
    f_single, f_body = single.frequencies(6), body.frequencies(6)
    np.testing.assert_allclose(f_body, f_single, rtol=SAME)
    s_single, s_body = single.static(LOAD), body.static(LOAD)
    U, V = np.meshgrid(np.linspace(0, 0.5, 6), np.linspace(0, 1 / split[1], 7), indexing="ij")
    scale = np.abs(s_single.displacement(U, V)).max()
    for p in range(len(patches)):
        xy = patches[p].evaluate(U, V)
        x, y = xy[..., 0], xy[..., 1]
        np.testing.assert_allclose(s_body.displacement(U, V, patch=p),
                                   s_single.displacement(x, y), rtol=0, atol=SAME * scale)


def test_quarters_meet_at_a_corner_of_four_and_one_interface_is_reversed() -> None:
    body = sd.Body(quarters())
    assert body.summary()["shared"] == 4 and body.summary()["boundary"] == 8
    assert any(i.reversed for i in body.interfaces)
    model = sd.BodyModel(body, MEMBRANE, boundary="free")
    # merged, the 4 × 6 × 6 control points are the 11 × 11 coefficients of the single patch
    assert model.n_free == split_square((2, 2), 3).shape[0] ** 2
    assert model.rigid_modes == 1      # free: one constant per coordinate
    # a constant field is the rigid motion: every patch's net moves as one
    nets = model.to_full(np.ones(model.n_free))
    assert [net.shape for net in nets] == [(6, 6)] * 4
    np.testing.assert_array_equal(np.concatenate(nets), 1.0)     # 0/1 entries of T: exact


def test_parametric_lumped_and_dynamic_paths_agree_with_single_patch() -> None:
    single_patch = split_square((2, 1), 3)
    for physics, mass in (("parametric", "consistent"), ("intrinsic", "lumped")):
        single = sd.Model(single_patch, MEMBRANE, boundary="clamped", physics=physics,
                          mass_matrix=mass)
        body = sd.BodyModel(halves(), MEMBRANE, boundary="clamped", physics=physics,
                            mass_matrix=mass)
        np.testing.assert_allclose(body.frequencies(6), single.frequencies(6), rtol=SAME)
    damped = sd.Material(w10=1.0, w01=1.0, damping=0.3)
    single = sd.Model(single_patch, damped, boundary="clamped", physics="intrinsic")
    body = sd.BodyModel(halves(), damped, boundary="clamped")
    a, b = single.dynamic(LOAD, 2.0), body.dynamic(LOAD, 2.0)
    nets = b.control_points(0.7)
    assert isinstance(nets, list) and nets[0].shape == halves()[0].shape + (3,)
    U, V = np.meshgrid(np.linspace(0, 0.5, 5), np.linspace(0, 1, 5), indexing="ij")
    scale = np.abs(a.displacement(0.7, U, V)).max()
    np.testing.assert_allclose(b.displacement(0.7, U, V, patch=0), a.displacement(0.7, U, V),
                               rtol=0, atol=SAME * scale)
    # energies are quadratic forms of the same state in another basis
    np.testing.assert_allclose(b.energy(0.7).total, a.energy(0.7).total, rtol=SAME)
    frames = b.frames([0.2, 0.7], resolution=5)
    assert len(frames.points) == 2 and frames.points[1].shape == (2, 5, 5, 3)
    # without rest shape the load has the extra part −K p0 of the same rest nets; lifted to
    # z = x y (1 − y) at the control points (the same surface both ways), p0 is not harmonic
    single = sd.Model(lifted(single_patch), MEMBRANE, boundary="pinned", physics="intrinsic",
                      rest="none").static(None)
    body_static = sd.BodyModel([lifted(h) for h in halves()], MEMBRANE, boundary="pinned",
                               rest="none").static(None)
    scale = np.abs(single.displacement(U, V)).max()
    np.testing.assert_allclose(body_static.displacement(U, V, patch=0),
                               single.displacement(U, V), rtol=0, atol=SAME * scale)


def test_point_load_on_a_patch() -> None:
    single = sd.Model(split_square((2, 1), 3), MEMBRANE, boundary="clamped", physics="intrinsic")
    body = sd.BodyModel(halves(), MEMBRANE, boundary="clamped")
    # patch 1 is reversed in u: its u = 0.1 is x = 0.9
    push = OnPatch(sd.Point(0.1, 0.3, (0.0, 0.0, -1.0)), patch=1)
    a, b = single.static(sd.Point(0.9, 0.3, (0.0, 0.0, -1.0))), body.static(push)
    U, V = np.meshgrid(np.linspace(0, 0.5, 5), np.linspace(0, 1, 5), indexing="ij")
    scale = np.abs(a.displacement(1 - U, V)).max()
    np.testing.assert_allclose(b.displacement(U, V, patch=1), a.displacement(1 - U, V),
                               rtol=0, atol=SAME * scale)
    with pytest.raises(sd.InputError, match="point load on a body needs its patch"):
        body.static(sd.Point(0.1, 0.3, (0.0, 0.0, -1.0)))
    with pytest.raises(sd.InputError, match="needs its patch"):
        body.static(LOAD).displacement(0.1, 0.1)


def test_given_interfaces_and_per_edge_boundary() -> None:
    patches = halves()
    given = [Interface(0, "u1", 1, "u1", reversed=False, conforming=True)]
    found = sd.Body(patches)
    assert list(found.interfaces) == given
    edges = {(0, "u0"): "clamped", (0, "v0"): "pinned", (1, "v1"): "pinned"}
    a = sd.BodyModel(sd.Body(patches, interfaces=given), MEMBRANE, boundary=edges)
    b = sd.BodyModel(found, MEMBRANE, boundary=edges)
    np.testing.assert_allclose(a.frequencies(4), b.frequencies(4), rtol=SAME)
    with pytest.raises(sd.InputError, match=r"edge u1 of patch 0 is an interface with edge u1 "
                                            r"of patch 1"):
        sd.BodyModel(found, MEMBRANE, boundary={(0, "u1"): "clamped"})


def test_non_conforming_interface_refined_to_conforming() -> None:
    fine = flat_patch((0.5, 1), (0, 1), (3, 3), reverse_u=True)
    coarse = flat_patch((0, 0.5), (0, 1), (3, 1))
    body = Body([coarse, fine])
    assert body.summary()["non_conforming"] == 1
    refined = body.conforming()
    assert refined.summary()["non_conforming"] == 0
    U, V = np.meshgrid(np.linspace(0, 0.5, 7), np.linspace(0, 1, 7), indexing="ij")
    # exact knot insertion: the geometry does not move (round-off of Boehm's convex sums)
    np.testing.assert_allclose(refined[0].evaluate(U, V), coarse.evaluate(U, V), atol=1e-14)
    model = sd.BodyModel(refined, MEMBRANE, boundary="clamped")
    single = sd.Model(split_square((2, 1), 3), MEMBRANE, boundary="clamped", physics="intrinsic")
    np.testing.assert_allclose(model.frequencies(6), single.frequencies(6), rtol=SAME)


def test_non_manifold_edge_is_refused() -> None:
    floor = flat_patch((0, 1), (0, 1), (2, 2))
    left = flat_patch((-1, 0), (0, 1), (2, 2))
    wall = sd.Surface(floor.control_points[:, :, [2, 1, 0]], floor.basis_u, floor.basis_v)
    body = Body([floor, left, wall])       # the wall x = 0 stands on the floors' edge
    assert body.summary()["non_manifold"] == 1
    with pytest.raises(sd.InputError, match=r"non-manifold edge: 3 patch edges meet"):
        sd.BodyModel(body, MEMBRANE)


@pytest.mark.parametrize("physics, twist, boundary, count", [
    # (Δd)² vanishes on the harmonic fields of bidegree <= (3, 3): 1, x, y, xy, x² − y²,
    # x³ − 3xy², 3x²y − y³, x³y − xy³ (C1 across the tied line, so harmonic on the whole
    # square); those vanishing on x = 0: x, xy, x³ − 3xy², x³y − xy³
    ("intrinsic", 1.0, "free", 8),
    ("intrinsic", 1.0, {(0, "u0"): "pinned"}, 4),
    # d_uu² + 2 w11 d_uv² + d_vv²: the fields 1, x, y (and xy where w11 = 0)
    ("parametric", 1.0, "free", 3),
    ("parametric", 0.0, "free", 4),
])
def test_a_free_bending_body_counts_its_rigid_modes(physics, twist, boundary, count) -> None:
    material = sd.Material(w20=1.0, w11=twist, w02=1.0)
    model = sd.BodyModel(halves(), material, boundary=boundary, physics=physics)
    assert model.rigid_modes == count
    assert model.constraints.ties.interfaces == {0}       # the halves' line tied C1
