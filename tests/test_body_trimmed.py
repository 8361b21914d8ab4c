"""Trimmed faces in a body, coupled along the trim curve they share.

The clamped unit square under a unit load, Hessian energy ``∫ (Δw)²`` (the Kirchhoff plate
with ``D = 1``, centre ``w = 0.00126532 q a⁴ / D``, Taylor & Govindjee 2004; Timoshenko &
Woinowsky-Krieger §44 give 0.00126), made of two trimmed faces of the same square: the
disc ``|x − c| < r`` and the square less that disc, its outer edges clamped, coupled along
the circle by the displacement and rotation penalties
(:mod:`splinedeform.physics.coupling_curves`).
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.body.interface import TrimInterface
from splinedeform.physics import coupling
from splinedeform.physics.coupling_curves import CurveSide
from splinedeform.physics.coupling_traces import Side
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain

from coupling_systems import CLAMPED_PLATE_CENTRE

PLATE = sd.Material(w20=1.0, w11=1.0, w02=1.0)
LOAD = sd.Uniform((0.0, 0.0, 1.0))
CENTRE, RADIUS = (0.5, 0.5), 0.3
SQUARE = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def split_square(disc_cells: int, ring_cells: int, degree: int = 4) -> sd.Body:
    """The disc and the square less the disc, each a trimmed unit square (open knots)."""
    circle = CircleLoop(CENTRE, RADIUS)
    disc = sd.shapes.plane(cells=(disc_cells,) * 2, degree=degree, knots="open")
    ring = sd.shapes.plane(cells=(ring_cells,) * 2, degree=degree, knots="open")
    return sd.Body([disc.with_trim(TrimDomain(circle)),
                    ring.with_trim(TrimDomain(SQUARE, (circle,)))])


def solve(body: sd.Body) -> tuple[float, float]:
    """Centre deflection and the largest jump across the circle over the largest
    displacement (both faces sampled on their regions)."""
    model = sd.BodyModel(body, PLATE, boundary="clamped", physics="parametric")
    static = model.static(LOAD)
    theta = np.linspace(0.0, 2.0 * np.pi, 400, endpoint=False)
    u, v = CENTRE[0] + RADIUS * np.cos(theta), CENTRE[1] + RADIUS * np.sin(theta)
    jump = static.displacement(u, v, patch=0) - static.displacement(u, v, patch=1)
    grid = np.linspace(0.0, 1.0, 41)
    U, V = (x.ravel() for x in np.meshgrid(grid, grid))
    inside = np.hypot(U - CENTRE[0], V - CENTRE[1]) < RADIUS
    largest = max(np.abs(static.displacement(U[inside], V[inside], patch=0)).max(),
                  np.abs(static.displacement(U[~inside], V[~inside], patch=1)).max())
    return float(static.displacement(*CENTRE, patch=0)[2]), float(np.abs(jump).max() / largest)


def test_the_faces_meet_along_the_circle_only():
    # the two faces are one square: their rectangle edges coincide, but the disc's lie
    # outside its region, so only the ring's edges are boundary edges
    body = split_square(8, 8)
    assert body.trim_interfaces == (TrimInterface(0, 0, 1, 1),)
    assert body.topology.interfaces == ()
    assert sorted(body.topology.boundary) == [(1, "u0"), (1, "u1"), (1, "v0"), (1, "v1")]


@pytest.mark.parametrize("cells", [(20, 20), (16, 24)], ids=["conforming", "non-conforming"])
def test_clamped_square_of_a_disc_and_a_holed_square(cells):
    # centre within 0.1 % of the closed form (quartic faces of 20 and 16-24 cells reach
    # 2.2e-7 and 2.8e-6); the jump across the circle is what the penalty and the
    # two faces' traces leave, 2.6e-7 and 8.7e-8 of the largest displacement: below 1e-6
    w, jump = solve(split_square(*cells))
    assert abs(w / CLAMPED_PLATE_CENTRE - 1) < 1e-3
    assert jump < 1e-6


def test_penalty_factor_over_a_decade():
    # over a decade of the penalty coefficient the centre of the 12-16 cell pair moves by
    # 5e-7, far less than its discretisation error (6.1e-5 of the closed form); the bar
    # 1e-5 keeps it below that error with room for round-off
    answers = []
    for scale in (10 ** -0.5, 10 ** 0.5):
        previous = coupling.PENALTY
        coupling.PENALTY = previous * scale
        try:
            answers.append(solve(split_square(12, 16))[0])
        finally:
            coupling.PENALTY = previous
    assert abs(answers[1] / answers[0] - 1) < 1e-5


def test_an_iso_edge_is_a_straight_trim_curve():
    # the rectangle's edge u = 1 as the second edge of a polygon loop gives the same trace
    # operators and conormal as the iso-edge (coupling_traces.Side); 1e-12 is round-off
    surface = sd.shapes.tile(cells=(4, 3))
    (_, lu), (_, lv) = surface.domain
    loop = PolygonLoop([[0.0, 0.0], [lu, 0.0], [lu, lv], [0.0, lv]])
    curve = CurveSide.of_loop(surface, loop)
    edge = Side.of_edge(surface, "u1")
    tau = np.linspace(0.05, 0.95, 7)
    along, across = curve.traces(1.0 + tau), edge.traces(tau * lv)
    scale = lv                                     # d/dt = L_v d/dv along the edge
    assert abs(along.values - across.values).max() < 1e-12
    assert abs(along.slopes - across.slopes).max() < 1e-12 * abs(across.slopes).max()
    assert np.abs(along.conormal - across.conormal).max() < 1e-12
    assert np.abs(along.speed - scale * across.speed).max() < 1e-12 * scale


def test_the_body_mesh_covers_each_face_on_its_region_only():
    # the welded mesh of the rest body (a flat square, x = (u, v, 0)): the disc's points
    # lie in the disc and the ring's outside it, to the loops' bisection round-off (1e-9),
    # and together their triangles cover the square once: both faces are sampled on one
    # grid, so the disc's chords of the circle are the ring's and the areas add up to 1
    # (to 1e-12, round-off of some 2000 triangles)
    from splinedeform.export.body import welded_body

    body = split_square(8, 12, degree=3)
    frames = [s.control_points[None] for s in body.patches]
    X, faces, patch = welded_body(body.patches, frames, 33)
    radius = np.hypot(X[0, :, 0] - CENTRE[0], X[0, :, 1] - CENTRE[1])
    assert radius[patch == 0].max() < RADIUS + 1e-9
    assert radius[patch == 1].min() > RADIUS - 1e-9
    a, b, c = (X[0, faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    assert abs(area - 1.0) < 1e-12


def test_frequencies_of_the_split_square():
    # the clamped square plate's lowest frequencies ω a² √(ρt/D) = 35.985, 73.394 (twice)
    # (Gorman, Free Vibration Analysis of Rectangular Plates, 1982; Leissa's Ritz values
    # 35.99 and 73.41 are upper bounds); the 12-16 cell pair reaches 1e-5, the bar is 1e-3
    model = sd.BodyModel(split_square(12, 16), PLATE, boundary="clamped",
                         physics="parametric")
    expected = np.array([35.985, 73.394, 73.394])
    assert np.max(np.abs(model.frequencies(3) / expected - 1)) < 1e-3


def test_trim_interfaces_given_by_hand_are_checked():
    # the found interface given by hand gives the same body; a loop that bounds nothing
    # (the ring's rectangle) or a face the body lacks is refused, naming it
    found = split_square(8, 8)
    given = sd.Body(found.patches, trim_interfaces=[TrimInterface(0, 0, 1, 1)])
    assert given.trim_interfaces == found.trim_interfaces
    with pytest.raises(sd.InputError, match="face 1 has no trim loop 0"):
        sd.Body(found.patches, trim_interfaces=[TrimInterface(0, 0, 1, 0)])
    with pytest.raises(sd.InputError, match="face 2 has no trim loop"):
        sd.Body(found.patches, trim_interfaces=[TrimInterface(0, 0, 2, 1)])


def test_a_trimmed_body_takes_the_intrinsic_energy():
    # the disc |x − c| < 0.3 and the square less it, clamped (docs/trim.md), under the
    # intrinsic plate (the default physics of a body): on a flat unit-speed face it is the
    # plate with (Δd)², the same clamped plate as the parametric one's; 12 × 12 cubic
    # cells each measured 2.0e-5 from 0.00126532 q a⁴/D (the parametric body 2.1e-5); 1e-4
    circle = CircleLoop((0.5, 0.5), 0.3)
    square = PolygonLoop([[0, 0], [1, 0], [1, 1], [0, 1]])
    plane = sd.shapes.plane(cells=(12, 12), degree=3, knots="open")
    body = sd.Body([plane.with_trim(TrimDomain(circle)),
                    plane.with_trim(TrimDomain(square, (circle,)))])
    model = sd.BodyModel(body, sd.Material(w20=1, w11=1, w02=1), boundary="clamped")
    w = model.static(sd.Uniform([0, 0, 1])).displacement(0.5, 0.5, patch=0)[2]
    assert abs(w / 0.00126532 - 1) < 1e-4
