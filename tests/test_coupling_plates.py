"""Bodies of two patches coupled across a non-conforming interface, and a plate with a C0
line, against one fine patch and the closed forms.

The unit square is split at x = 1/2 into a left patch of 6 × 12 cubic spans and a right one
of 4 × 8 (different knots along the interface, none shared but 0, 1/4, 1/2, 3/4, 1).
Each answer is compared with one patch of 48 × 48 spans (the reference) and held to the
discretisation error of the coarser side, estimated as the error of one 8 × 8 patch
against that reference.
"""

from __future__ import annotations

import numpy as np
import pytest

from splinedeform.body import Interface
from splinedeform.physics import coupling

from coupling_systems import (CLAMPED_PLATE_CENTRE, MEMBRANE, PLATE, c0_basis, flat_patch,
                              left_half, offsets, single, solve, uniform, value)

SPLIT = Interface(0, "u1", 1, "u0", conforming=False)
POISSON_CENTRE = 0.0736713532
"""``u(1/2, 1/2)`` of ``−Δu = 1`` on the unit square, ``u = 0`` on its boundary (the double
sine series summed to 10 digits)."""
REFERENCE_CELLS = 48
COARSER_CELLS = 8


def split_body(degree_b: int = 3):
    return [flat_patch(0.0, 0.5, 6, 12), flat_patch(0.5, 0.5, 4, 8, degree=degree_b)]


def boundaries(edge: str):
    """The outer edges held; the interface edges free (the penalties couple them)."""
    return [{"u0": edge, "v0": edge, "v1": edge}, {"u1": edge, "v0": edge, "v1": edge}]


def split_centre(material, edge, f, scale=1.0, rotation=True, projected=True, degree_b=3):
    """Centre deflection (from the left patch) and the jump to the right patch there."""
    patches = split_body(degree_b)
    o = offsets(patches)
    h = coupling.interface_size(patches, SPLIT)
    alpha, beta = coupling.penalty_factors(material, h)
    held = coupling.HELD[edge]
    K = coupling.displacement_penalty(patches, SPLIT, scale * alpha, o, projected, held)
    if beta and rotation:
        K = K + coupling.rotation_penalty(patches, SPLIT, scale * beta, o, projected, held)
    d_left, d_right = solve(patches, [0.0, 0.5], boundaries(edge), material, K, f)
    w = value(patches[0], d_left, 0.5, 0.5)
    return w, value(patches[1], d_right, 0.0, 0.5) - w


def discretisation(material, edge, f, degree=3):
    reference = single(REFERENCE_CELLS, material, edge, f)
    return reference, abs(single(COARSER_CELLS, material, edge, f, degree) - reference)


@pytest.mark.parametrize("degree_b", [3, 2])
def test_split_membrane_matches_one_patch_over_a_decade_of_penalties(degree_b):
    # the load on the left half only, so that the interface carries the flux (a load
    # symmetric about x = 1/2 would leave it without any)
    reference, error = discretisation(MEMBRANE, "pinned", left_half, degree_b)
    answers = [split_centre(MEMBRANE, "pinned", left_half, scale, degree_b=degree_b)
               for scale in (10 ** -0.5, 1.0, 10 ** 0.5)]
    w = np.array([a[0] for a in answers])
    # within the discretisation error of the coarser side (1e-5 .. 4e-5 relative)
    assert np.abs(w - reference).max() <= error
    # a decade of α around the default moves the answer by less than that error
    assert np.ptp(w) <= error
    # the two sides meet at the centre to within that error too
    assert abs(answers[1][1]) <= error


def test_split_membrane_under_a_uniform_load_meets_the_closed_form():
    reference, error = discretisation(MEMBRANE, "pinned", uniform)
    assert reference == pytest.approx(POISSON_CENTRE, rel=1e-7)   # 48² cubic spans: 3e-9
    w, jump = split_centre(MEMBRANE, "pinned", uniform)
    assert abs(w - POISSON_CENTRE) <= error + 1e-9 * POISSON_CENTRE   # + the series' digits
    assert abs(jump) <= error


def test_the_plain_penalty_locks_where_the_projected_one_does_not():
    reference, error = discretisation(MEMBRANE, "pinned", left_half)
    plain = [split_centre(MEMBRANE, "pinned", left_half, s, projected=False)[0]
             for s in (1e-2, 1.0)]
    projected = [split_centre(MEMBRANE, "pinned", left_half, s)[0] for s in (1e-2, 1.0)]
    # C = 10³ to 10⁵: the plain penalty's answer moves by many times the discretisation
    # error as it forces unrelated traces to agree; the projected one settles
    assert abs(plain[1] - plain[0]) > 5 * error
    assert abs(plain[1] - reference) > 5 * error
    assert abs(projected[1] - reference) <= error


@pytest.mark.parametrize("f", [uniform, left_half])
def test_split_plate_bends_like_one_plate_and_like_a_hinge_without_the_rotation(f):
    reference, error = discretisation(PLATE, "clamped", f)
    if f is uniform:
        # the fine patch against Timoshenko's series (5 digits: 4e-5 of it)
        assert reference == pytest.approx(CLAMPED_PLATE_CENTRE, rel=4e-5)
    answers = [split_centre(PLATE, "clamped", f, scale) for scale in (10 ** -0.5, 1.0, 10 ** 0.5)]
    w = np.array([a[0] for a in answers])
    assert np.abs(w - reference).max() <= error          # 1.4e-4 relative
    assert np.ptp(w) <= error
    assert abs(answers[1][1]) <= error
    # the displacement tied, the rotation free: a hinge along x = 1/2, which sags
    hinge, _ = split_centre(PLATE, "clamped", f, rotation=False)
    assert hinge / reference > 1.1


def c0_plate():
    return flat_patch(0.0, 1.0, 8, 8, basis_u=c0_basis(3, 8))


def c0_centre(beta_scale: float):
    surface = c0_plate()
    (line,) = coupling.c0_lines(surface)
    beta = coupling.penalty_factors(PLATE, coupling.c0_size(surface, *line))[1]
    K = coupling.c0_rotation_penalty(surface, *line, beta_scale * beta)
    (d,) = solve([surface], [0.0], ["clamped"], PLATE, K, uniform)
    return surface, d


def test_a_c0_line_with_the_rotation_penalty_bends_like_the_smooth_plate():
    reference, error = discretisation(PLATE, "clamped", uniform)
    smooth = single(COARSER_CELLS, PLATE, "clamped")
    surface, d = c0_centre(1.0)
    w = value(surface, d, 0.5, 0.5)
    # the C0 basis holds the smooth one, and the penalty takes it back there: the two
    # differ by a tenth of the smooth 8 × 8 plate's own error at most (measured: 1e-6 of
    # the deflection against 1.4e-4)
    assert abs(w - smooth) <= 0.1 * error
    # the slope jump across the line, against the largest slope (measured: 5.6e-6 at C = 1e5)
    v = np.linspace(0.0, 1.0, 41)
    net = d.reshape(surface.shape + (1,))
    below = surface.derivative(0.5 - 1e-12, v, 1, 0, net)      # the last point of the left span
    above = surface.derivative(0.5, v, 1, 0, net)
    x = np.linspace(0.0, 1.0, 81)
    slopes = surface.derivative(x[:, None], x[None, :], 1, 0, net)
    jump = np.abs(above - below).max() / np.abs(slopes).max()
    assert jump < 1e-5
    # without it the line is a hinge
    surface, d = c0_centre(0.0)
    assert value(surface, d, 0.5, 0.5) / reference > 1.1
