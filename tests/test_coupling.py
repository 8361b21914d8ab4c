"""The coupling operators on their own: exact energies of known fields across an interface."""

from __future__ import annotations

import numpy as np
import pytest

from splinedeform.basis import BSplineBasis
from splinedeform.body import Interface
from splinedeform.errors import InputError
from splinedeform.knots import KnotVectorBasis, RationalBasis, one_sided
from splinedeform.physics import coupling
from splinedeform.physics.coupling_traces import merged
from splinedeform.shapes import from_function
from splinedeform.surface import Surface

from coupling_systems import MEMBRANE, PLATE, c0_basis, flat_patch, offsets

SPLIT = Interface(0, "u1", 1, "u0", conforming=False)


def tilted(surface: Surface) -> Surface:
    """The patch under ``x ↦ A x`` with ``A`` a rotation times a stretch of 2 in y.

    The interface (along y) becomes 2 long, and both edges are moved alike.
    """
    c, s = np.cos(0.7), np.sin(0.7)
    A = np.array([[c, 0.0, -s], [0.0, 2.0, 0.0], [s, 0.0, c]])
    return surface.with_control_points(surface.control_points @ A.T)


def interpolant(surface: Surface, field) -> np.ndarray:
    """Control values of ``field(x, y)`` by collocation at the Greville points (exact for a
    polynomial in the spline space)."""
    gu, gv = surface.basis_u.greville(), surface.basis_v.greville()
    Bu, Bv = surface.basis_u(gu), surface.basis_v(gv)
    X = surface.evaluate_grid(gu, gv)
    values = field(X[..., 0], X[..., 1])
    return np.linalg.solve(Bv, np.linalg.solve(Bu, values).T).T.ravel()


def two_patches(degree_b: int = 2) -> list[Surface]:
    """Left 4 × 8 cubic spans, right 3 × 5 of ``degree_b``: no common knot inside x = 1/2."""
    return [flat_patch(0.0, 0.5, 4, 8), flat_patch(0.5, 0.5, 3, 5, degree=degree_b)]


@pytest.mark.parametrize("projected", [True, False])
def test_a_unit_jump_costs_half_alpha_times_the_interface_length(projected):
    patches = [tilted(p) for p in two_patches()]
    K = coupling.displacement_penalty(patches, SPLIT, 3.0, offsets(patches), projected)
    d = np.concatenate([np.ones(patches[0].shape[0] * patches[0].shape[1]),
                        np.zeros(patches[1].shape[0] * patches[1].shape[1])])
    # ½ α |Γ| = ½ · 3 · 2, the length measured on the rest surface (a constant lies in both
    # trace spaces, so the projection keeps it); quadrature exact: round-off, 1e-12
    assert 0.5 * d @ K @ d == pytest.approx(3.0, rel=1e-12)
    assert abs(K - K.T).max() <= 1e-14 * abs(K).max()            # symmetric to round-off


def test_a_smooth_field_costs_nothing_and_a_kink_its_slope_jump():
    flat = two_patches(degree_b=3)
    patches = [tilted(p) for p in flat]
    o = offsets(patches)
    D = coupling.displacement_penalty(patches, SPLIT, 1.0, o)
    R = coupling.rotation_penalty(patches, SPLIT, 1.0, o)
    # fields of the flat positions (x, y): the tilt moves the rest shape, not the control
    # values; lengths along x are kept, along y doubled
    quadratic = lambda x, y: 1 + x - 2 * y + 3 * x * y + x ** 2 - y ** 2     # noqa: E731
    smooth = np.concatenate([interpolant(p, quadratic) for p in flat])
    ones = np.ones(D.shape[0])
    unit = 0.5 * ones @ (abs(D) + abs(R)) @ ones
    # a quadratic lies in both patches' spaces: both jumps vanish to the round-off of
    # O(1) entries summed over the edge, 1e-11 of the matrices' size
    assert abs(smooth @ D @ smooth) <= 1e-11 * unit
    assert abs(smooth @ R @ smooth) <= 1e-11 * unit
    # |x - 1/2| added (each side's own polynomial): no displacement jump, a slope of -1 out
    # of each side, so (∂n d_a + ∂n d_b)² = 4 on |Γ| = 2: ½ β · 4 · 2 = 4 (exact, 1e-10)
    kinked = np.concatenate([interpolant(p, lambda x, y, k=k: quadratic(x, y) + k * (x - 0.5))
                             for p, k in zip(flat, (-1.0, 1.0))])
    assert abs(kinked @ D @ kinked) <= 1e-11 * unit
    assert 0.5 * kinked @ R @ kinked == pytest.approx(4.0, rel=1e-10)


def test_a_curved_interface_is_measured_on_the_rest_surface():
    # two cubic fits of a quarter cylinder of radius 1, 8 and 5 spans around, meeting at
    # z = 1/2 along an arc whose two drawings differ by their fit errors (3e-5)
    def cylinder(u, v):
        return np.stack([np.cos(u), np.sin(u), v], -1)

    below = from_function(cylinder, cells=(8, 4), domain=((0, np.pi / 2), (0, 0.5)))
    above = from_function(cylinder, cells=(5, 3), domain=((0, np.pi / 2), (0.5, 1.0)))
    patches, interface = [below, above], Interface(0, "v1", 1, "v0", conforming=False)
    o = offsets(patches)
    D = coupling.displacement_penalty(patches, interface, 1.0, o)
    R = coupling.rotation_penalty(patches, interface, 1.0, o)
    # the length of the lower patch's top edge, as a polyline of 20001 points (relative
    # error (Δs κ)² / 24 ~ 3e-10): the quadrature of the non-polynomial |x_s| to 1e-8
    s = np.linspace(0.0, np.pi / 2, 20001)
    edge = below.evaluate(s, np.full_like(s, 0.5))
    length = np.linalg.norm(np.diff(edge, axis=0), axis=1).sum()
    unit = np.concatenate([np.ones(o[1]), np.zeros(D.shape[0] - o[1])])
    assert 0.5 * unit @ D @ unit == pytest.approx(0.5 * length, rel=1e-8)
    # the height z is smooth across (slopes +1 and -1 out of the two sides): nothing to
    # pay; |z - 1/2| has a slope of -1 out of each: ½ · 2² · |Γ|, to 1e-8 as the length
    # (measured 5e-10: z is exact in both fits, and their conormals are the z axis)
    z = np.concatenate([p.control_points[..., 2].ravel() for p in patches])
    assert abs(z @ R @ z) <= 1e-9
    kink = np.concatenate([0.5 - below.control_points[..., 2].ravel(),
                           above.control_points[..., 2].ravel() - 0.5])
    assert 0.5 * kink @ R @ kink == pytest.approx(2.0 * length, rel=1e-8)


def test_an_exact_circular_interface_of_nurbs_patches():
    # a quarter cylinder as NURBS (weights 1, √½, 1 around), cut at z = 1/2 into 3 and 2
    # spans of height: the interface is an exact quarter circle, π/2 long
    around = RationalBasis(KnotVectorBasis(2, [0, 0, 0, 1, 1, 1]), [1, 0.5 ** 0.5, 1])
    arc = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])

    def wall(z0: float, cells: int) -> Surface:
        up = BSplineBasis(2, cells, 0.5, "open")
        g = up.greville()
        P = np.stack(np.broadcast_arrays(arc[:, None, 0], arc[:, None, 1], z0 + g[None, :]), -1)
        return Surface(P, around, up)

    patches = [wall(0.0, 3), wall(0.5, 2)]
    o = offsets(patches)
    D = coupling.displacement_penalty(patches, Interface(0, "v1", 1, "v0"), 1.0, o)
    unit = np.concatenate([np.ones(o[1]), np.zeros(D.shape[0] - o[1])])
    # the rational basis' own 14 Gauss points per span: round-off, 1e-13
    assert 0.5 * unit @ D @ unit == pytest.approx(np.pi / 4, rel=1e-13)
    # inside a span the one-sided values of a rational basis are its values (round-off)
    index, values = around.nonzero_derivatives(0.3, 1)
    for side in (-1, 1):
        i, v = one_sided(around, 0.3, side, 1)
        np.testing.assert_array_equal(i, index)
        np.testing.assert_allclose(v, values, rtol=1e-14, atol=1e-14)


def test_a_reversed_interface_gives_the_same_energies():
    left, right = two_patches()
    mirrored = Surface(right.control_points[:, ::-1], right.basis_u, right.basis_v)
    kink = lambda x, y: np.abs(x - 0.5) + y ** 2 * (1 + x)       # noqa: E731
    for patches, interface in (([left, right], SPLIT),
                               ([left, mirrored], Interface(0, "u1", 1, "u0", reversed=True,
                                                            conforming=False))):
        o = offsets(patches)
        d = np.concatenate([interpolant(p, kink) for p in patches])
        energies = [0.5 * d @ coupling.displacement_penalty(patches, interface, 1.0, o) @ d,
                    0.5 * d @ coupling.rotation_penalty(patches, interface, 1.0, o) @ d]
        if interface is SPLIT:
            expected = energies
    # the same field on the same body: the same energies whichever way b runs, up to the
    # round-off of two quadrature orders (1e-12 of the energy)
    np.testing.assert_allclose(energies, expected, rtol=1e-12, atol=1e-14)


def test_edges_that_do_not_meet_are_refused_by_name():
    patches = two_patches()
    with pytest.raises(InputError, match=r"interface .*u1.* do not meet.*reversed"):
        coupling.displacement_penalty(patches, Interface(0, "u1", 1, "u1"), 1.0,
                                      offsets(patches))
    with pytest.raises(InputError, match="patch 2"):
        coupling.rotation_penalty(patches, Interface(0, "u1", 2, "u0"), 1.0, offsets(patches))


def test_penalty_factors_scale_with_the_material_and_the_element_size():
    patches = two_patches()
    h = coupling.interface_size(patches, SPLIT)
    assert h == pytest.approx(1.0 / 8.0, rel=1e-12)    # the finer edge: 8 spans of 1/8
    alpha, beta = coupling.penalty_factors(MEMBRANE, h)
    assert (alpha, beta) == (pytest.approx(coupling.PENALTY * 8.0, rel=1e-12), 0.0)
    alpha, beta = coupling.penalty_factors(PLATE, h)
    assert alpha == pytest.approx(coupling.PENALTY * 8.0 ** 3, rel=1e-12)
    assert beta == pytest.approx(coupling.PENALTY * 8.0, rel=1e-12)


def test_c0_lines_and_one_sided_slopes():
    surface = flat_patch(0.0, 1.0, 8, 8, basis_u=c0_basis(3, 8))
    assert coupling.c0_lines(surface) == [("u", 0.5)]
    assert coupling.c0_lines(flat_patch(0.0, 1.0, 8, 8)) == []
    with pytest.raises(InputError, match="not a C0 knot line"):
        coupling.c0_rotation_penalty(surface, "u", 0.25, 1.0)
    # one-sided derivatives of a degree-2 basis at its C0 knot: ±4 = 2/(1/2) (exact)
    b = KnotVectorBasis(2, [0, 0, 0, 0.5, 0.5, 1, 1, 1])
    np.testing.assert_array_equal(one_sided(b, 0.5, -1)[0], [0, 1, 2])
    np.testing.assert_allclose(one_sided(b, 0.5, -1)[1][1], [0, -4, 4], atol=1e-14)
    np.testing.assert_allclose(one_sided(b, 0.5, +1)[1][1], [-4, 4, 0], atol=1e-14)
    # a kink |u - 1/2| (in the space: the knot is C0) costs ½ β · 2² · 1 = 2β; u² nothing
    for field, energy in ((lambda x, y: np.abs(x - 0.5), 2.0), (lambda x, y: x ** 2 + y, 0.0)):
        d = interpolant(surface, field)
        R = coupling.c0_rotation_penalty(surface, "u", 0.5, 1.0)
        assert 0.5 * d @ R @ d == pytest.approx(energy, abs=1e-10)   # round-off, O(1) sums


def test_the_projection_needs_a_trace_space_longer_than_its_merged_ends():
    with pytest.raises(InputError, match="cannot merge"):
        merged(BSplineBasis(1, 1, 1.0, "open").matrix([0.2, 0.7]), 1, 1)
    # merged ends keep the partition of unity: one at every point, to round-off
    space = merged(BSplineBasis(3, 5, 1.0, "open").matrix([0.1, 0.5, 0.9]), 2, 1)
    assert space.shape == (3, 5)
    np.testing.assert_allclose(np.asarray(space.sum(axis=1)).ravel(), 1.0, rtol=1e-14)


def test_bad_ends_and_factors_are_refused_by_name():
    patches = two_patches()
    with pytest.raises(InputError, match="interface end is one of .*'glued'"):
        coupling.interface_penalty(patches, SPLIT, PLATE, offsets(patches), ("glued", "free"))
    with pytest.raises(InputError, match="penalty factor is finite and >= 0"):
        coupling.rotation_penalty(patches, SPLIT, -1.0, offsets(patches))
    with pytest.raises(InputError, match="offsets has 1 entries for 2 patches"):
        coupling.displacement_penalty(patches, SPLIT, 1.0, [0])
