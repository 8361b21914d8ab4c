"""A shell body from a scenario (scenario/body.py, outputs_body_shell.py, probes_body.py):
the Scordelis–Lo roof as two exact NURBS faces of a .3dm file, written here, run through
``splinedeform run``.

Roof (as tests/test_shell_body.py): radius 25, length 50 along y, 80° of arc, t = 0.25,
E = 4.32e8, ν = 0, self-weight 90 per unit area, rigid diaphragms at y = 0 and y = L, free
sides. Each face is 40° of the arc, a rational quadratic in u (weights 1, cos 20°, 1: the
circle exactly) and a quadratic straight line in v (parameter v = y); the scenario elevates
both to cubic and inserts 3 knots per span (4 × 4 spans per face). The two faces are plain
surfaces, not a Brep: the reader joins them where their edges meet.
Reference: vertical displacement 0.3006163 at the middle of a free edge (PENGoLINS, 9
non-matching patches; the converged Kirchhoff–Love value of the obstacle course, 0.3006).
"""

import json
from math import cos, pi, sin

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli

pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
meshio = pytest.importorskip("meshio")

runner = CliRunner()
R, L, HALF = 25.0, 50.0, 40 * pi / 180
REFERENCE = 0.3006163
#: the free edge u = 0 of face 0 (the arc's end at -40°) at midspan
FREE_EDGE = (R * sin(-HALF), L / 2, R * cos(-HALF))


def roof_face(a0: float, a1: float):
    """The arc from angle ``a0`` to ``a1`` (from the crest, about the y axis), exactly."""
    from splinedeform.cad import NurbsPatch

    h, m = 0.5 * (a1 - a0), 0.5 * (a0 + a1)
    arc = [(R * sin(a0), R * cos(a0)), (R / cos(h) * sin(m), R / cos(h) * cos(m)),
           (R * sin(a1), R * cos(a1))]
    points = np.array([[[x, y, z] for y in (0.0, L / 2, L)] for x, z in arc])
    weights = np.array([[1.0] * 3, [cos(h)] * 3, [1.0] * 3])
    knots = np.array([0, 0, 0, 1, 1, 1.0])
    return NurbsPatch((2, 2), knots, knots * L, points, weights)


@pytest.fixture(scope="module")
def roof_3dm(tmp_path_factory):
    from splinedeform.cad import write_3dm

    path = tmp_path_factory.mktemp("roof") / "roof.3dm"
    return write_3dm(path, [roof_face(-HALF, 0.0), roof_face(0.0, HALF)])


def roof_scenario(folder, source, solve='kind = "static"\nframes = 2', output=""):
    import shutil

    shutil.copy(source, folder / source.name)
    path = folder / "roof.toml"
    path.write_text(
        f'[surface]\nshape = "cad"\npath = "{source.name}"\nelevate = 1\nrefine = 3\n'
        '[material]\nphysics = "shell"\nE = 4.32e8\nnu = 0.0\nthickness = 0.25\n'
        '[boundary.faces]\n0 = {v0 = "diaphragm", v1 = "diaphragm"}\n'
        '1 = {v0 = "diaphragm", v1 = "diaphragm"}\n'
        '[[load]]\nkind = "uniform"\nforce = [0.0, 0.0, -90.0]\n'
        f'[solve]\n{solve}\n[output]\nresolution = 9\n{output}\n')
    return path


def test_the_scordelis_lo_roof_of_two_cad_faces_runs_from_the_command_line(roof_3dm,
                                                                          tmp_path):
    point = ", ".join(repr(x) for x in FREE_EDGE)
    scenario = roof_scenario(tmp_path, roof_3dm, output=(
        'formats = ["report", "vtu", "images"]\n'
        f'probes = [[0.0, 25.0], [{point}]]\nprobe_faces = [0, 0]\n'))
    out = tmp_path / "out"
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["body"]["topology"]["shared"] == 1     # joined where the faces meet
    assert report["body"]["degrees"] == [[3, 3], [3, 3]]
    w = -report["probes"]["face 0 (0, 25) dz"][-1]
    # measured 0.300180 (4 × 4 cubic spans per face, 0.14 % low: the discretisation error;
    # the crest tied exactly, tests/test_shell_ties.py)
    assert w == pytest.approx(REFERENCE, rel=0.005)
    # the point in space on the free edge is found on face 0 at (0, 25): its nearest point
    # to round-off of the Gauss–Newton search (1e-9 of the displacement)
    (name,) = {k.rsplit(" ", 1)[0] for k in report["probes"] if k.startswith("point")}
    assert "on face 0 (0, 25)" in name
    assert -report["probes"][f"{name} dz"][-1] == pytest.approx(w, rel=1e-9)
    # the stresses per face, where a single shell's run writes them
    assert set(report["stresses"]) == {"face 0", "face 1"}
    # the roof is symmetric about its crest: the two faces' largest von Mises agree to the
    # round-off of the solve (1e-9 relative)
    top = [report["stresses"][f"face {k}"]["max von Mises top"] for k in (0, 1)]
    assert top[0] > 0 and top[1] == pytest.approx(top[0], rel=1e-9)
    assert "face 0 (0, 25) von Mises top" in report["probe stresses"]
    mesh = meshio.read(out / "roof_0001.vtu")
    assert {"von_mises_top", "membrane_force", "bending_moment"} <= set(mesh.point_data)
    assert (out / "stresses.png").exists()


def test_the_nearest_face_of_a_point_probe(roof_3dm, tmp_path):
    """Without probe_faces a point is read on the face it is nearest to."""
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    mirrored = (-FREE_EDGE[0], FREE_EDGE[1], FREE_EDGE[2])
    scenario = roof_scenario(tmp_path, roof_3dm, output=(
        f'probes = [[{", ".join(map(repr, FREE_EDGE))}], [{", ".join(map(repr, mirrored))}]]'))
    result = run(load_scenario(scenario), tmp_path / "out")
    names = list(result.probes)
    assert "on face 0 (0, 25)" in names[0] and "on face 1 (1, 25)" in names[1]
    # the two free edges' midpoints, mirror images: the same vertical displacement to
    # round-off of the solve (1e-9 relative)
    a, b = (result.probes[n][-1] for n in names)
    assert b[2] == pytest.approx(a[2], rel=1e-9) and a[2] < 0


def test_modes_and_dynamics_of_the_shell_roof(roof_3dm, tmp_path):
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    modes = run(load_scenario(roof_scenario(tmp_path, roof_3dm, 'kind = "modes"\nmodes = 3\n'
                                            'frames = 3', 'formats = ["report", "gif"]')),
                tmp_path / "modes")
    # the diaphragms hold the ends in their planes only: the one rigid motion left is the
    # translation along the axis, ω = 0 (to round-off, 1e-6 of the largest ω); the others
    # vibrate
    assert modes.built.model.rigid_motions == ["translation along (0, 1, 0)"]
    assert modes.omegas[0] <= 1e-6 * modes.omegas[-1] and modes.omegas[1] > 0
    assert len(modes.shell_modes) == 2 and modes.shell_modes[0].shape == (3, 7, 7, 3)
    report = json.loads((tmp_path / "modes" / "report.json").read_text())
    assert len(report["modes"]["max von Mises top (mass-normalised shape)"]) == 3
    assert (tmp_path / "modes" / "roof.gif").exists()
    dynamic = run(load_scenario(roof_scenario(
        tmp_path, roof_3dm, 'kind = "dynamic"\nt_end = 0.05\nframes = 4\nmodes = 0',
        'formats = ["report"]')), tmp_path / "dynamic")
    # the undamped closed form under a constant load conserves kinetic + strain − work
    # (round-off: measured 3e-10 of the work; 1e-8 leaves a margin)
    total, work = dynamic.energy["total"], dynamic.energy["work"]
    assert np.abs(total).max() <= 1e-8 * np.abs(work).max()


def test_a_body_probe_is_checked_at_its_key(roof_3dm, tmp_path):
    from splinedeform.errors import ScenarioError
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    def refusal(output):
        with pytest.raises(ScenarioError) as info:
            run(load_scenario(roof_scenario(tmp_path, roof_3dm, output=output)),
                tmp_path / "out")
        return str(info.value)

    assert "output.probes[1]: [u, v] on a body needs its face" in refusal(
        "probes = [[0.0, 25.0]]")
    assert "output.probe_faces: gives 2 face(s) for 1 probe(s)" in refusal(
        "probes = [[0.0, 25.0]]\nprobe_faces = [0, 1]")
    assert "output.probe_faces[1]: face 4 is not in this body, whose faces are [0, 1]" in \
        refusal("probes = [[0.0, 25.0]]\nprobe_faces = [4]")
    assert "output.probes[1]: v = 60 is outside the parameter domain [0, 50]" in refusal(
        "probes = [[0.0, 60.0]]\nprobe_faces = [0]")
