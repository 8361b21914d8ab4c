"""T-junctions of untrimmed faces: a clamped square of three patches.

The left half ``[0, 0.5] × [0, 1]`` is one patch; the right half is two patches stacked,
``[0.5, 1] × [0, 0.5]`` and ``[0.5, 1] × [0.5, 1]``, so that the left patch's edge
``u1`` shares one half with each of the right patches' edges ``u0`` and the right
patches' common corner ``(0.5, 0.5)`` lies in the middle of it. The right patches meet
along a whole conforming edge (merged); the two stretches of ``u1`` are coupled by the
stretch penalties. Clamped all round under a uniform load, the centre deflection is
Kirchhoff's ``w = 0.00126532 q a⁴ / D`` (Timoshenko & Woinowsky-Krieger, table 35) for
the thin plate (the Hessian energy, parametric) and for the Kirchhoff–Love shell.

Cells: the left patch has ``n × 2n`` cubic cells, each right one ``m × m``. With
``m = n / 2`` the right traces lie in the left's running space (their knots are some of
the left's), so the coupled gap can vanish and falls with the penalty factor; with
``m = 3n / 4`` it cannot, and what remains is the part of the right trace outside the
left's space (a discretisation error, independent of the penalty).
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.body.interface import TrimEdgeInterface
from splinedeform.cad import NurbsPatch
from splinedeform.cad_faces import topology_line
from splinedeform.cad_topology import body_topology
from splinedeform.physics import coupling
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import AreaForce, ShellModel

REFERENCE = 0.00126532
PLATE = sd.Material(w20=1.0, w11=1.0, w02=1.0)
SHELL = ShellMaterial(E=1.0, nu=0.3, thickness=0.01)
D_SHELL = SHELL.E * SHELL.thickness ** 3 / (12.0 * (1.0 - SHELL.nu ** 2))


def three_patches(n: int, m: int) -> sd.Body:
    left = sd.shapes.plane(size=(0.5, 1.0), cells=(n, 2 * n))
    small = sd.shapes.plane(size=(0.5, 0.5), cells=(m, m))
    return sd.Body([left] + [small.with_control_points(small.control_points + [0.5, y, 0.0])
                             for y in (0.0, 0.5)])


def solve(physics: str, n: int, m: int, scale: float = 1.0):
    """The static solution of the clamped square under a unit load and its centre
    deflection ``w D / (q a⁴)``, the penalty factor scaled by ``scale``."""
    previous = coupling.PENALTY
    coupling.PENALTY = previous * scale
    try:
        if physics == "plate":
            model = sd.BodyModel(three_patches(n, m), PLATE, boundary="clamped",
                                 physics="parametric")
            static, stiffness = model.static(sd.Uniform([0.0, 0.0, 1.0])), 1.0
        else:
            model = ShellModel(three_patches(n, m), SHELL, "clamped")
            static, stiffness = model.static(AreaForce(force=(0.0, 0.0, 1.0))), D_SHELL
    finally:
        coupling.PENALTY = previous
    return static, float(static.displacement(0.5, 0.5, patch=0)[2]) * stiffness


def gap(static, samples: int = 201) -> float:
    """The largest jump of the displacement along ``x = 0.5``, relative to the centre
    deflection (the largest displacement of the clamped square), each side read at its
    own parameters of the same points."""
    y = np.linspace(0.0, 1.0, samples)
    left = static.displacement(np.full(samples, 0.5), y, patch=0)
    low = static.displacement(np.zeros(samples), np.minimum(y, 0.5), patch=1)
    high = static.displacement(np.zeros(samples), np.maximum(y - 0.5, 0.0), patch=2)
    right = np.where((y <= 0.5)[:, None], low, high)
    largest = float(np.abs(static.displacement(0.5, 0.5, patch=0)).max())
    return float(np.abs(left - right).max()) / largest


def test_the_left_edge_shares_a_stretch_with_each_right_patch():
    body = three_patches(4, 3)
    # every count is an integer: compared to 0.5
    counts = body.summary()
    assert abs(counts["shared"] - 1) < 0.5 and abs(counts["partly_shared"] - 2) < 0.5
    assert abs(counts["boundary"] - 7) < 0.5          # u1 of the left and u0 of the right
    assert {(i.a, i.edge_a, i.b, i.edge_b) for i in body.edge_interfaces} == {
        (0, "u1", 1, "u0"), (0, "u1", 2, "u0")}
    for interface in body.edge_interfaces:
        assert isinstance(interface, TrimEdgeInterface)
        # the left edge u1 is t in [1, 2] of its rectangle's polygon, cut at its middle;
        # the right ones' u0 is [3, 4], run downwards (from v = 0.5 to 0): the stretch
        # ends to round-off of the projection (1e-9 of a parameter unit)
        low = 1.0 if interface.b == 1 else 1.5
        assert np.allclose(interface.part_a, (low, low + 0.5), atol=1e-9)
        assert np.allclose(interface.part_b, (4.0, 3.0), atol=1e-9)
    assert "partly_shared" not in sd.Body([sd.shapes.plane()]).summary()


@pytest.mark.parametrize("physics", ["plate", "shell"])
def test_the_three_patches_bend_like_one_square(physics):
    for n, m in ((8, 4), (8, 6)):
        static, w = solve(physics, n, m)
        # discretisation error: the one-patch square of 8 × 8 cubic cells (the coarsest
        # net here, per unit length) is 1.4e-4 below the closed form; found 7.2e-5 and
        # 3.0e-5
        assert abs(w / REFERENCE - 1) < 3e-4, (n, m, w / REFERENCE - 1)
        # the gap: 4.6e-7 (plate) and 9.8e-10 (shell) with nested knots, 1.5e-4 without
        assert gap(static) < 1e-3


@pytest.mark.parametrize("physics", ["plate", "shell"])
def test_the_gap_falls_a_decade_with_the_penalty_where_the_traces_can_meet(physics):
    static, w = solve(physics, 8, 4)
    stiffer, w_stiff = solve(physics, 8, 4, scale=10.0)
    # nested knots: the whole jump lies in the trace space, so it scales like 1 / α
    # (found a factor 10.0 for both)
    assert 7.0 < gap(static) / gap(stiffer) < 13.0
    # the deflection moves by far less than its discretisation error (3e-4): found 1e-6
    assert abs(w_stiff / w - 1) < 3e-5


@pytest.mark.parametrize("physics", ["plate", "shell"])
def test_held_ends_are_merged_so_a_stiffer_penalty_does_not_lock(physics):
    # non-nested knots: the gap left is the right trace outside the left's space, the
    # same over a decade of penalty factors (1.505e-4 both, to 1e-3 of itself), and the
    # clamped ends of the stretches are not tied twice (the shell moved by 6e-4 of its
    # deflection over the decade with them tied twice; 3e-6 now)
    static, w = solve(physics, 8, 6)
    stiffer, w_stiff = solve(physics, 8, 6, scale=10.0)
    assert abs(gap(stiffer) / gap(static) - 1) < 1e-2
    assert abs(w_stiff / w - 1) < 3e-5


def sheet(corner, du, dv) -> NurbsPatch:
    """The flat biquadratic file face ``corner + s du + t dv`` on ``[0, 1]²``."""
    s = np.linspace(0.0, 1.0, 3)
    P = (np.asarray(corner, float) + s[:, None, None] * np.asarray(du, float)
         + s[None, :, None] * np.asarray(dv, float))
    knots = np.array([0, 0, 0, 1, 1, 1.0])
    return NurbsPatch((2, 2), knots, knots, P, np.ones((3, 3)))


def file_edge(faces, a, b):
    """An edge from ``a`` to ``b`` used by ``faces``, sampled as the readers sample it."""
    t = (np.arange(9) + 0.5) / 9
    return {"faces": faces, "points": np.asarray(a, float) + t[:, None] * np.subtract(b, a)}


def test_a_file_s_t_junction_edges_are_listed_and_left_to_the_stretches():
    # a Brep of the three-patch square: the left face's side x = 0.5 split into two
    # edges, each also a side of one right face (as a sewn shell has it)
    patches = [sheet([0, 0, 0], [0.5, 0, 0], [0, 1, 0]),
               sheet([0.5, 0, 0], [0.5, 0, 0], [0, 0.5, 0]),
               sheet([0.5, 0.5, 0], [0.5, 0, 0], [0, 0.5, 0])]
    edges = [file_edge([0, 1], [0.5, 0, 0], [0.5, 0.5, 0]),
             file_edge([0, 2], [0.5, 0.5, 0], [0.5, 1, 0]),
             file_edge([1, 2], [0.5, 0.5, 0], [1, 0.5, 0])]
    topology = body_topology(patches, edges, [0, 1, 2])
    # counts are integers: compared to 0.5
    assert abs(topology.counts["shared"] - 3) < 0.5
    assert abs(topology.counts["partly_shared"] - 2) < 0.5
    assert [(i.a, i.edge_a, i.b, i.edge_b) for i in topology.interfaces] == [
        (1, "v1", 2, "v0")]
    line = topology_line(topology.as_dict())
    assert "3 shared" in line and "2 of them along part of a side" in line
    # the body made with the file's interfaces finds and couples the two stretches
    body = sd.Body(three_patches(4, 3), topology.interfaces)
    assert abs(body.summary()["partly_shared"] - 2) < 0.5
    assert abs(body.summary()["boundary"] - 7) < 0.5
