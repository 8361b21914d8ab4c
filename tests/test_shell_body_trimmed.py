"""The Kirchhoff–Love shell on bodies with trimmed faces (:mod:`splinedeform.physics.shell_body_trimmed`).

* A flat unit square made of two trimmed faces, the disc ``|x − c| < 0.3`` and the square
  less that disc, clamped on the square's edges (Nitsche's terms of the holed rectangle)
  and pressed by a uniform pressure: the same plate as the untrimmed clamped square shell,
  whose centre is Kirchhoff's ``0.00126532 q a⁴ / D`` (Taylor & Govindjee 2004).
* The drilled box (2 × 2 × 1 less a cylinder of radius 0.4, from OpenCASCADE): seven faces,
  the top and the bottom squares with a hole, pressed from inside, free.
"""

from __future__ import annotations

import json
import shutil
import warnings

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

import splinedeform as sd
from splinedeform import cli
from splinedeform.physics import coupling
from splinedeform.physics.coupling_curves import CurveSide, curve_line
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_body import body_field
from splinedeform.physics.shell_model import ShellModel
from splinedeform.scenario import build, load_scenario
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain

from coupling_systems import CLAMPED_PLATE_CENTRE

E, NU, THICKNESS = 1.0e4, 0.3, 0.02
SHELL = ShellMaterial(E, NU, THICKNESS, 1.0)
D = E * THICKNESS ** 3 / (12 * (1 - NU ** 2))
CIRCLE = CircleLoop((0.5, 0.5), 0.3)
SQUARE = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
EDGES = ("u0", "u1", "v0", "v1")


def split_square(disc_cells: int, ring_cells: int) -> sd.Body:
    """The disc and the square less the disc, quartic trimmed unit squares."""
    disc = sd.shapes.plane(cells=(disc_cells,) * 2, degree=4, knots="open")
    ring = sd.shapes.plane(cells=(ring_cells,) * 2, degree=4, knots="open")
    return sd.Body([disc.with_trim(TrimDomain(CIRCLE)),
                    ring.with_trim(TrimDomain(SQUARE, (CIRCLE,)))])


def pressed(body: sd.Body, scale: float = 1.0):
    """The clamped body's static solution under ``q = 1``, the penalty factor scaled."""
    previous = coupling.PENALTY
    coupling.PENALTY = previous * scale
    try:
        model = ShellModel(body, SHELL, "clamped")
    finally:
        coupling.PENALTY = previous
    return model, model.static(sd.Pressure(1.0))


def largest(static) -> float:
    return max(float(np.abs(d).max()) for d in static.net_displacement())


def test_the_split_square_is_the_clamped_square_shell():
    body = split_square(12, 12)
    model, static = pressed(body)
    assert model.rigid.shape[1] == 0            # clamped by Nitsche's terms: nothing free
    square = sd.shapes.plane(cells=(12, 12), degree=4, knots="open")
    whole = ShellModel(square, SHELL, {e: "clamped" for e in EDGES}).static(sd.Pressure(1.0))
    # the deflection on a grid of each face's region against the untrimmed square's: the
    # 12 × 12 quartic square is within 4e-7 of Kirchhoff's centre, the split one within
    # 1.2e-5 (the cut cells, the penalty along the circle); 1e-4 of the largest deflection
    # bounds that discretisation error with room
    grid = np.linspace(0.02, 0.98, 25)
    U, V = (x.ravel() for x in np.meshgrid(grid, grid))
    inside = np.hypot(U - 0.5, V - 0.5) < 0.3
    w = np.concatenate([static.displacement(U[inside], V[inside], patch=0),
                        static.displacement(U[~inside], V[~inside], patch=1)])
    w_ref = np.concatenate([whole.displacement(U[inside], V[inside]),
                            whole.displacement(U[~inside], V[~inside])])
    peak = np.abs(w_ref).max()
    assert np.abs(w - w_ref).max() < 1e-4 * peak
    # flat: no in-plane motion to round-off (1e-9 of the deflection)
    assert np.abs(w[:, :2]).max() < 1e-9 * peak
    centre = static.displacement(0.5, 0.5, patch=0)[2]
    assert abs(centre / (CLAMPED_PLATE_CENTRE / D) - 1) < 1e-4


def test_the_split_square_vibrates_as_the_clamped_square_shell():
    # the four lowest eigenvalues ω² (one double) of the 12 × 12 quartic pair against the
    # untrimmed square's: 1.4e-6 to 1.0e-5 apart; 1e-4 bounds that discretisation error
    split = ShellModel(split_square(12, 12), SHELL, "clamped").eigen(4)[0]
    square = sd.shapes.plane(cells=(12, 12), degree=4, knots="open")
    whole = ShellModel(square, SHELL, {e: "clamped" for e in EDGES}).eigen(4)[0]
    assert np.all(np.abs(split / whole - 1) < 1e-4)


def projected_jump(body: sd.Body, static) -> float:
    """The largest ``|Π (d_a − d_b)|`` at the circle's quadrature points: the part of the
    jump in the trace space that the displacement penalty measures."""
    a, b = (CurveSide.of_loop(body.patches[p], CIRCLE) for p in (0, 1))
    line, _ = curve_line(a, b, "the circle")
    nets = static.net_displacement()
    jump = (line.sides[0].values @ nets[0].reshape(-1, 3)
            - line.sides[1].values @ nets[1].reshape(-1, 3))
    Phi, W = line.space(0).toarray(), line.weights[:, None]
    return float(np.abs(Phi @ np.linalg.solve(Phi.T @ (W * Phi), Phi.T @ (W * jump))).max())


def test_the_gap_along_the_circle_and_the_penalty():
    body = split_square(12, 16)                 # non-conforming along the circle
    theta = np.linspace(0.0, 2.0 * np.pi, 400, endpoint=False)
    u, v = 0.5 + 0.3 * np.cos(theta), 0.5 + 0.3 * np.sin(theta)
    gaps, projected, centres = [], [], []
    for scale in (1.0, 10.0):
        _, static = pressed(body, scale)
        jump = static.displacement(u, v, patch=0) - static.displacement(u, v, patch=1)
        gaps.append(np.abs(jump).max() / largest(static))
        projected.append(projected_jump(body, static) / largest(static))
        centres.append(static.displacement(0.5, 0.5, patch=0)[2])
    # the gap is 9.4e-7 of the largest displacement: below 1e-3 with room
    assert max(gaps) < 1e-3
    # what the penalty measures falls a decade with it (3.0e-9 → 3.0e-10, ratio 10.0;
    # bar [7, 13]); the rest of the gap is the part of the faces' traces that no spline
    # along the circle holds (their cells' crossings of it), the same 9.4e-7 for both
    # factors (within 10 %): a discretisation error
    assert 7 < projected[0] / projected[1] < 13
    assert abs(gaps[1] / gaps[0] - 1) < 0.1
    # and the centre moves by 1e-8 of itself over the decade (bar 1e-6)
    assert abs(centres[1] / centres[0] - 1) < 1e-6


#: the membrane's drilled box scenario (tests/test_body_trim_edges_cad.py) as a thin shell
SHELL_MATERIAL = 'physics = "shell"\nE = 1.0e4\nnu = 0.3\nthickness = 0.02'


@pytest.fixture(scope="module")
def drilled_box(tmp_path_factory):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from test_body_trim_edges_cad import SCENARIO
    from test_body_trim_edges_cad import drilled_box as made

    folder = made.__wrapped__(tmp_path_factory).parent
    membrane = 'w10 = 1.0\nw01 = 1.0\nphysics = "parametric"'
    assert membrane in SCENARIO
    (folder / "shell.toml").write_text(SCENARIO.format(path="drilled.step", refine=3)
                                       .replace(membrane, SHELL_MATERIAL))
    return folder


def test_the_drilled_box_is_one_trimmed_shell(drilled_box):
    from test_body_trim_edges_cad import gaps

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        built = build(load_scenario(drilled_box / "shell.toml"))
    assert not [w for w in caught if "whole underlying surface" in str(w.message)]
    body, model = built.surface, built.model
    assert isinstance(model, ShellModel)
    assert sum(s.trim is not None for s in body.patches) == 2    # the top and the bottom
    assert model.rigid.shape[1] == 6                             # free: all six
    # the pressure's resultant and moment vanish to round-off (measured 1.3e-14 of
    # q times the area; bar 1e-10)
    F = body_field(body.patches, built.load, 0.0, body.orientation).reshape(-1, 3)
    P = np.concatenate([s.control_points.reshape(-1, 3) for s in body.patches])
    area = 2 * (4 - np.pi * 0.16) + 4 * 2 + 2 * np.pi * 0.4
    assert np.abs(F.sum(axis=0)).max() < 1e-10 * area
    assert np.abs(np.cross(P, F).sum(axis=0)).max() < 1e-10 * area
    static = model.static(built.load)
    peak = largest(static)
    found = gaps(body, static)
    # the iso-edges' gaps are the penalty's, 2e-8 of the largest displacement; the holes'
    # 2.6e-4, the part of the top's trace the wall's edge space cannot hold (as for the
    # plate, tests/test_body_trim_edges_cad.py): all below 1e-3
    assert found.max() < 1e-3 * peak
    # and each flat face's own resultant is q times its area along its outward normal
    # (away from the box's centre; the top and the bottom 4 − 0.16 π, the sides 2), to
    # the accuracy of the trimmed quadrature (1e-10 of the area)
    for p, surface in enumerate(body.patches):
        own = F[model.offsets[p]:model.offsets[p + 1]].sum(axis=0)
        net = surface.control_points.reshape(-1, 3)
        flat = np.ptp(net, axis=0) < 1e-9
        if not flat.any():
            continue                                          # the wall of the hole
        axis = int(np.argmax(flat))
        outward = np.zeros(3)
        outward[axis] = np.sign(net[0, axis] - (1.0, 1.0, 0.5)[axis])
        size = 4 - 0.16 * np.pi if axis == 2 else 2.0
        assert np.abs(own - size * outward).max() < 1e-10 * size


def test_a_scenario_run_of_the_drilled_shell_box(drilled_box, tmp_path):
    shutil.copy(drilled_box / "drilled.step", tmp_path / "drilled.step")
    shutil.copy(drilled_box / "shell.toml", tmp_path / "shell.toml")
    result = CliRunner().invoke(cli.app, ["run", str(tmp_path / "shell.toml"), "-o",
                                          str(tmp_path / "out"), "-q"])
    assert result.exit_code == 0, result.output
    assert "whole underlying surface" not in result.output
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["body"]["trim edges"] == {"shared": 2, "free": 0, "stretches": 2}
    assert report["body"]["patches"] == 7 and "stresses" in report
    last = sorted((tmp_path / "out").glob("shell_*.vtu"))[-1]
    mesh = meshio.read(last)
    d, normal = mesh.point_data["displacement"], mesh.point_data["normal_displacement"]
    assert np.isfinite(mesh.point_data["von_mises_top"]).all()
    # each point's stresses are its own: on the flat top and bottom (trimmed, clipped
    # meshes) the normal displacement is ±d_z at every point (to 1e-9 of the largest)
    flat = (np.abs(mesh.points[:, 2] - 1.0) < 1e-9) | (np.abs(mesh.points[:, 2]) < 1e-9)
    sides = (np.abs(mesh.points[:, 0] - 1.0) > 1.0 - 1e-9) | \
        (np.abs(mesh.points[:, 1] - 1.0) > 1.0 - 1e-9)        # the box's edges: two faces
    hole = np.hypot(mesh.points[:, 0] - 1.0, mesh.points[:, 1] - 1.0) < 0.4 + 1e-9
    on = flat & ~sides & ~hole
    assert on.sum() > 50
    scale = np.abs(d).max()
    assert np.abs(np.abs(normal[on]) - np.abs(d[on, 2])).max() < 1e-9 * scale


def test_a_trimmed_shell_s_stress_fields_follow_its_clipped_mesh(tmp_path):
    from splinedeform.export import write_time_series
    from splinedeform.export.shell_fields import stress_fields

    plane = sd.shapes.plane(cells=(8, 8), degree=4, knots="open")
    surface = plane.with_trim(TrimDomain(CIRCLE))
    model = ShellModel(surface, SHELL, {"outer": "clamped"})
    rest = surface.control_points
    nets = (rest + model.static(sd.Pressure(1.0)).net_displacement())[None]
    fields = stress_fields(model, rest, nets, 9)
    write_time_series(tmp_path, "disc", surface, rest, [0.0], nets, 9, fields)
    mesh = meshio.read(tmp_path / "disc_0000.vtu")
    d, normal = mesh.point_data["displacement"], mesh.point_data["normal_displacement"]
    # every point of the disc's clipped mesh (grid points inside and points on the circle)
    # carries its own stresses: on the flat disc the normal displacement is ±d_z, to 1e-9
    # of the largest
    assert len(d) > 40 and np.abs(d[:, 2]).max() > 0
    assert np.abs(np.abs(normal) - np.abs(d[:, 2])).max() < 1e-9 * np.abs(d).max()


def test_a_shell_body_s_faces_with_general_weights_keep_their_trim():
    # the plane's net with weights that do not factor: the same flat unit square, its
    # parametrisation warped; the disc and the square less it (the same circle in
    # parameters, so the same curve) clamped on the square's edges are the clamped square
    # plate. Its largest deflection sampled on an 81² parameter grid against Kirchhoff's
    # centre: measured 1.7e-5; 1e-3 bounds the sampling of a flat peak (the nearest
    # samples lie within 0.006 of the centre, where w falls by about 3e-4) and the
    # discretisation error of 8 × 8 quartic cells (~1e-5)
    from dataclasses import replace

    plane = sd.shapes.plane(cells=(8, 8), degree=4, knots="open")
    u = np.arange(plane.shape[0])[:, None]
    v = np.arange(plane.shape[1])[None, :]
    weighted = replace(plane, net_weights=1.0 + 0.1 * np.sin(u + 2.0 * v) ** 2)  # no product
    assert sd.rational.product_factors(weighted.net_weights) is None
    one = ShellModel(weighted.with_trim(TrimDomain(CIRCLE)), SHELL, {"outer": "clamped"})
    assert one.rigid.shape[1] == 0                     # one face: held by its loop
    body = sd.Body([weighted.with_trim(TrimDomain(CIRCLE)),
                    weighted.with_trim(TrimDomain(SQUARE, (CIRCLE,)))])
    static = ShellModel(body, SHELL, "clamped").static(sd.Pressure(1.0))
    grid = np.linspace(0.0, 1.0, 81)
    U, V = (x.ravel() for x in np.meshgrid(grid, grid))
    X = weighted.evaluate(U, V)
    near = np.hypot(X[:, 0] - 0.5, X[:, 1] - 0.5) < 0.29           # inside the disc face
    peak = np.abs(static.displacement(U[near], V[near], patch=0)).max()
    assert abs(peak * D / CLAMPED_PLATE_CENTRE - 1) < 1e-3


def test_a_trimmed_shell_body_s_boundary_by_edge_and_loop():
    body = split_square(8, 8)
    one = ShellModel(body, SHELL, "clamped").static(sd.Pressure(1.0))
    each = ShellModel(body, SHELL, {(1, e): "clamped" for e in EDGES}).static(sd.Pressure(1.0))
    # the same edges held, named one by one: the same system, to round-off (1e-12)
    a, b = one.displacement(0.5, 0.5, patch=0), each.displacement(0.5, 0.5, patch=0)
    assert np.abs(a - b).max() < 1e-12 * np.abs(a).max()
    # the circle is shared by the two faces: it takes no condition
    with pytest.raises(sd.errors.InputError, match="shared with another face"):
        ShellModel(body, SHELL, {(0, "outer"): "clamped"})
