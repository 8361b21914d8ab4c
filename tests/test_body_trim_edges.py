"""Trim edges shared in part: a flat T of an untrimmed strip and a trimmed square on it.

The strip ``[0, 3] × [0, 1]`` (an untrimmed face, its edge ``y = 0`` clamped) carries the
square ``[1, 2] × [1, 2]``, a face trimmed out of the rectangle ``[0.9, 2.1] × [0.95,
2.15]`` (so that its trim lines cross its knot cells): the square's bottom trim edge is
the middle third of the strip's top edge ``v1``. A uniform load on the thin plate (the
Hessian energy ``∫ w_uu² + 2 w_uv² + w_vv²``, parametric, both faces parametrised by
``x, y``). The reference is the same T as four untrimmed patches meeting along whole,
conforming edges, their control points merged
(:class:`~splinedeform.body.constraints.BodyConstraints`).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.body.trim_edges import corner_labels, edge_curve, side
from splinedeform.physics import coupling
from splinedeform.physics.coupling_curves import curve_line, curve_points
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain

PLATE = sd.Material(w20=1.0, w11=1.0, w02=1.0)
LOAD = sd.Uniform((0.0, 0.0, 1.0))
#: the square's trim loop in its own parameters (x = u + 0.9, y = v + 0.95)
SQUARE = PolygonLoop([[0.1, 0.05], [1.1, 0.05], [1.1, 1.05], [0.1, 1.05]])


def moved(surface: sd.Surface, dx: float, dy: float) -> sd.Surface:
    return surface.with_control_points(surface.control_points + [dx, dy, 0.0])


def t_plate(m: int) -> sd.Body:
    """The strip and the trimmed square, ``m`` cells per unit length, cubic."""
    strip = sd.shapes.plane(size=(3.0, 1.0), cells=(3 * m, m))
    square = moved(sd.shapes.plane(size=(1.2, 1.2), cells=(round(1.2 * m),) * 2), 0.9, 0.95)
    return sd.Body([strip, square.with_trim(TrimDomain(SQUARE))])


def conforming_t(m: int) -> sd.Body:
    """The same T as four unit squares of ``m × m`` cells."""
    unit = sd.shapes.plane(cells=(m, m))
    return sd.Body([moved(unit, x, y) for x, y in ((0, 0), (1, 0), (2, 0), (1, 1))])


def tip(body: sd.Body, clamped: list[tuple[int, str]], at: tuple[float, float], patch: int,
        scale: float = 1.0) -> tuple[float, sd.body.BodyModel, object]:
    """Deflection at the top middle of the square (``x, y = 1.5, 2``), the model and its
    static solution, the penalty factor scaled by ``scale``."""
    previous = coupling.PENALTY
    coupling.PENALTY = previous * scale
    try:
        model = sd.BodyModel(body, PLATE, boundary={e: "clamped" for e in clamped},
                             physics="parametric")
    finally:
        coupling.PENALTY = previous
    static = model.static(LOAD)
    return float(static.displacement(*at, patch=patch)[2]), model, static


def coupled_tip(m: int, scale: float = 1.0):
    return tip(t_plate(m), [(0, "v0")], (0.6, 1.05), 1, scale)


@functools.lru_cache(maxsize=None)
def reference_tip(m: int) -> float:
    return tip(conforming_t(m), [(0, "v0"), (1, "v0"), (2, "v0")], (0.5, 1.0), 3)[0]


def stretch_gap(body: sd.Body, static, samples: int = 201) -> float:
    """The largest jump of the displacement along the shared stretch, each side read at
    its own parameters of the same points (the strip's at ``y = 1``, the square's at
    ``v = 0.05``)."""
    x = np.linspace(1.0, 2.0, samples)
    strip = static.displacement(x, np.ones(samples), patch=0)
    square = static.displacement(x - 0.9, np.full(samples, 0.05), patch=1)
    return float(np.abs(strip - square).max())


def largest_displacement(static) -> float:
    """The largest displacement on the T, sampled on both faces' regions."""
    x, y = np.meshgrid(np.linspace(0.0, 3.0, 31), np.linspace(0.0, 1.0, 11))
    u, v = np.meshgrid(np.linspace(0.1, 1.1, 11), np.linspace(0.05, 1.05, 11))
    return float(max(np.abs(static.displacement(x.ravel(), y.ravel(), patch=0)).max(),
                     np.abs(static.displacement(u.ravel(), v.ravel(), patch=1)).max()))


def test_the_square_shares_the_middle_of_the_strips_edge():
    # the square's first trim edge (its bottom, from its first corner) and the middle
    # third of the strip's edge v1, run the other way (the strip's rectangle runs its top
    # edge from x = 3 to 0: segment 2 of its polygon, t = 2 + (3 − x) / 3); parameters
    # from closest-point projection, 1e-9 for its round-off
    body = t_plate(4)
    (joint,) = body.edge_interfaces
    assert (joint.a, joint.edge_a, joint.b, joint.edge_b) == (1, "outer.0", 0, "v1")
    assert joint.part_a == pytest.approx((0.0, 1.0), abs=1e-9)
    assert joint.part_b == pytest.approx((2.0 + 2.0 / 3.0, 2.0 + 1.0 / 3.0), abs=1e-9)
    # the strip's shared edge is no boundary edge any more: its other three are
    assert sorted(body.topology.boundary) == [(0, "u0"), (0, "u1"), (0, "v0")]
    assert body.trim_summary() == {"shared": 1, "free": 3, "stretches": 1}
    # the stretch's two curves are the same points, to round-off
    a = side(body.patches, edge_curve(body.patches, 1, "outer.0"), joint.part_a)
    b = side(body.patches, edge_curve(body.patches, 0, "v1"), joint.part_b)
    t = np.linspace(0.0, 1.0, 9)
    s = joint.part_b[0] + t * (joint.part_b[1] - joint.part_b[0])
    assert np.abs(a.position(t)[0] - b.position(s)[0]).max() < 1e-12


def test_the_coupled_t_is_the_conforming_t_within_its_discretisation_error():
    # 10 cells per unit: the coupled T's tip is 1.0839616, the conforming T's 1.0853035
    # and, at 20 cells per unit, 1.0865195: the two models differ by 1.34e-3, about the
    # conforming model's own change under refinement (1.22e-3; the re-entrant corners at
    # (1, 1) and (2, 1) make it converge slowly); the bar is 1.5 times that change
    coupled = coupled_tip(10)[0]
    coarse, fine = reference_tip(10), reference_tip(20)
    assert abs(coupled - coarse) < 1.5 * abs(fine - coarse)
    # and refined alike, the coupled T moves towards the conforming one's limit: at 20
    # cells per unit it is 1.0855127, 1.0e-3 from the conforming 20-cell answer
    assert abs(coupled_tip(20)[0] - fine) < abs(coupled - coarse)


def test_the_gap_along_the_stretch_falls_a_decade_with_the_penalty():
    # the jump across the stretch is what the penalty leaves (factor α = C D / h³, C =
    # coupling.PENALTY = 1e5): 1.9e-6 of the largest displacement (bar 1e-3), and 1.9e-7
    # with C ten times larger (ratio 9.94; bar [7, 13], "about a decade"); the tip moves
    # by 1.1e-5 of itself meanwhile, far below the discretisation error (1.2e-3 above)
    first, model, static = coupled_tip(10)
    second, _, stiffer = coupled_tip(10, scale=10.0)
    body = model.body
    largest = largest_displacement(static)
    gap, gap_stiff = stretch_gap(body, static), stretch_gap(body, stiffer)
    assert gap < 1e-3 * largest
    assert 7.0 < gap / gap_stiff < 13.0
    assert abs(second / first - 1) < 1e-4


def test_corners_split_a_polygon_loop_into_trim_edges():
    # vertex 1 lies on the segment from vertex 0 to vertex 2 (no corner): five segments,
    # four trim edges; a circle is one edge
    loop = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    assert corner_labels(loop) == (0, 0, 1, 2, 3)
    assert corner_labels(CircleLoop((0.5, 0.5), 0.3)) is None
    # in a body the square's loop is split at its corners: outer.0 … outer.3
    body = t_plate(4)
    assert body.patches[1].trim.edge_count(0) == 4
    # the stretch's points in the square's parameters lie on its bottom, v = 0.05
    (joint,) = body.edge_interfaces
    uv = curve_points(body.patches[1].trim.outer, np.linspace(*joint.part_a, 5))[0]
    assert np.abs(uv[:, 1] - 0.05).max() < 1e-12


def test_a_shared_trim_edge_takes_no_condition():
    with pytest.raises(sd.InputError, match=r"outer\.0 of face 1 is shared with another face"):
        sd.BodyModel(t_plate(4), PLATE, boundary={(0, "v0"): "clamped",
                                                   (1, "outer.0"): "clamped"},
                     physics="parametric")
    # the square's free top edge can be held by its name
    held = sd.BodyModel(t_plate(4), PLATE, boundary={(0, "v0"): "clamped",
                                                     (1, "outer.2"): "clamped"},
                        physics="parametric")
    assert held.constraints.edges[(1, "outer.2")] == "clamped"
    assert held.constraints.edges[(1, "outer.0")] == "free"


def both_trimmed(m: int) -> sd.Body:
    """The T with the strip trimmed too, out of the rectangle ``[−0.07, 3.07] × [−0.07,
    1.07]`` (its trim lines off its knot lines): the strip's top trim edge (``outer.2``)
    shares its middle third with the square's bottom one."""
    strip = moved(sd.shapes.plane(size=(3.14, 1.14), cells=(round(3.14 * m), round(1.14 * m))),
                  -0.07, -0.07)
    loop = PolygonLoop([[0.07, 0.07], [3.07, 0.07], [3.07, 1.07], [0.07, 1.07]])
    square = moved(sd.shapes.plane(size=(1.2, 1.2), cells=(round(1.2 * m),) * 2), 0.9, 0.95)
    return sd.Body([strip.with_trim(TrimDomain(loop)), square.with_trim(TrimDomain(SQUARE))])


def projected_jump(body: sd.Body, static) -> float:
    """The largest ``|Π (d_a − d_b)|`` at the quadrature points of the body's one stretch:
    the part of the jump in the trace space, which the penalty measures."""
    (joint,) = body.edge_interfaces
    a = side(body.patches, edge_curve(body.patches, joint.a, joint.edge_a), joint.part_a)
    b = side(body.patches, edge_curve(body.patches, joint.b, joint.edge_b), joint.part_b)
    (c0, c1), (s0, s1) = joint.part_a, joint.part_b
    line, _ = curve_line(a, b, "", lambda t: s0 + (np.asarray(t) - c0) * (s1 - s0) / (c1 - c0))
    nets = static.net_displacement()
    jump = (line.sides[0].values @ nets[joint.a].reshape(-1, 3)
            - line.sides[1].values @ nets[joint.b].reshape(-1, 3))
    Phi, W = line.space(0).toarray(), line.weights[:, None]
    return float(np.abs(Phi @ np.linalg.solve(Phi.T @ (W * Phi), Phi.T @ (W * jump))).max())


def test_two_trimmed_faces_share_part_of_their_trim_edges():
    body = both_trimmed(10)
    (joint,) = body.edge_interfaces
    assert (joint.edge_a, joint.edge_b) == ("outer.2", "outer.0")
    assert body.trim_summary() == {"shared": 2, "free": 6, "stretches": 1}
    # the strip's bottom, its first trim edge, clamped (by Nitsche's terms): the tip is
    # 1.0837302, 1.57e-3 from the conforming T of 10 cells per unit, whose own change to 20
    # cells is 1.22e-3 (bar: 1.5 times that)
    w, model, static = tip(body, [(0, "outer.0")], (0.6, 1.05), 1)
    assert abs(w - reference_tip(10)) < 1.5 * abs(reference_tip(20) - reference_tip(10))
    # the gap along the stretch: 8.3e-6 of the largest displacement (bar 1e-3), what the
    # two faces' traces (their knots 0.1013 and 0.1 apart) cannot share, a discretisation
    # error; the part of it in the trace space (the finer side's knots) is the penalty's
    # and falls a decade with the factor (measured ratio 10.0; bar [7, 13])
    _, _, stiff = tip(body, [(0, "outer.0")], (0.6, 1.05), 1, scale=10.0)
    x = np.linspace(1.0, 2.0, 201)
    gap = np.abs(static.displacement(x + 0.07, np.full(x.size, 1.07), patch=0)
                 - static.displacement(x - 0.9, np.full(x.size, 0.05), patch=1)).max()
    assert gap < 1e-3 * abs(w)
    assert 7.0 < projected_jump(body, static) / projected_jump(body, stiff) < 13.0
