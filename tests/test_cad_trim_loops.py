"""The trim loops of a CAD face held from a scenario (``[boundary.loops]``): a disc-trimmed
plane written by rhino3dm, clamped on its outer loop, against the closed form
``q a⁴/(64 D)`` and against the same disc given by hand (``[surface.trim]``); a square
turned by 45° in a plane's parameter box, written by OpenCASCADE as four trim edges, two
opposite ones pinned (``outer.0``, ``outer.2``), against the strip's closed form; located
errors and the names ``splinedeform faces`` lists."""

import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import splinedeform as sd
from splinedeform import cli
from splinedeform.errors import ScenarioError
from trim_scenario import TAIL

A = 0.5                                   # the disc's radius; its box is [0, 1]²
LOAD = sd.Uniform([0.0, 0.0, 1.0])        # q = 1 per unit area


def face(path, refine):
    """``[surface]`` of face 0 of ``path`` on its trimmed region, cubic on
    ``(refine + 1)²`` cells (degree 1 on one cell raised by 2, ``refine`` knots inserted)."""
    return (f'[surface]\nshape = "cad"\npath = "{path}"\nface = 0\nelevate = [2, 2]\n'
            f"refine = [{refine}, {refine}]\ntrimmed = true\n")


#: the disc face on 12 × 12 cubic cells, clamped on its rim
DISC = face("disc.3dm", 11) + '[boundary.loops]\nouter = "clamped"\n'
#: the same disc by hand: the same cells, degree and (open) knots, the exact circle
HAND = """
[surface]
shape = "plane"
size = [1.0, 1.0]
cells = 12
degree = 3
knots = "open"
[[surface.trim.loops]]
circle = { centre = [0.5, 0.5], radius = 0.5 }
edge = "clamped"
"""
#: the plate's material (D = 1), load (q = 1) and static solve
PLATE = TAIL
#: the turned square, a membrane on 6 × 6 cubic cells, its edges held as ``{loops}``
SQUARE = (face("square.step", 5) + "[boundary.loops]\n{loops}\n"
          + TAIL.replace("w20 = 1.0\nw11 = 1.0\nw02 = 1.0\n", "w10 = 1.0\nw01 = 1.0\n"))
#: the square's corners in the plane (x, y) = its parameters (u, v), counter-clockwise
CORNERS = [(0.5, 0.0), (1.0, 0.5), (0.5, 1.0), (0.0, 0.5)]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A folder with ``disc.3dm`` (rhino3dm: the plane trimmed by the circle of radius
    ``A`` about (0.5, 0.5)) and ``square.step`` (OpenCASCADE: the planar face of the
    polygon ``CORNERS``, one trim edge per side)."""
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.gp import gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    out = tmp_path_factory.mktemp("faces")
    model = r3.File3dm()
    circle = r3.NurbsCurve.CreateFromCircle(r3.Circle(r3.Point3d(0.5, 0.5, 0.0), A))
    model.Objects.AddBrep(r3.Brep.CreateTrimmedPlane(r3.Plane.WorldXY(), circle))
    assert model.Write(str(out / "disc.3dm"), 7)
    polygon = BRepBuilderAPI_MakePolygon()
    for x, y in CORNERS:
        polygon.Add(gp_Pnt(x, y, 0.0))
    polygon.Close()
    writer = STEPControl_Writer()
    writer.Transfer(BRepBuilderAPI_MakeFace(polygon.Wire()).Face(), STEPControl_AsIs)
    writer.Write(str(out / "square.step"))
    return out


def _built(folder, name, text):
    from splinedeform.scenario import build, load_scenario

    path = folder / f"{name}.toml"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the planes are unbounded surfaces
        return build(load_scenario(path))


def _static(folder, name, text):
    return _built(folder, name, text).model.static(LOAD)


def test_a_clamped_disc_face_against_the_closed_form(folder):
    # w0 = q a⁴/(64 D) (Timoshenko & Woinowsky-Krieger §62), D = 1 (w20 = w11 = w02, ν = 0);
    # 12 × 12 cubic cells reach 3e-5 (as the disc given by hand does); 0.1 % is the bar
    centre = _static(folder, "disc", DISC + PLATE).displacement(0.5, 0.5)[2]
    assert abs(centre / (A ** 4 / 64) - 1) < 1e-3


SHELL = TAIL.replace("w20 = 1.0\nw11 = 1.0\nw02 = 1.0",
                     'physics = "shell"\nE = 10000.0\nnu = 0.3\nthickness = 0.01')


@pytest.mark.parametrize("edge, closed_form", [
    ("clamped", 1.0),                      # q a⁴/(64 D)
    ("pinned", 5.3 / 1.3),                 # (5 + ν)/(1 + ν) of it
])
def test_a_disc_face_as_a_shell_against_the_closed_form(folder, edge, closed_form):
    # the thin shell (E t³/(12(1 − ν²)) = D) bends as Kirchhoff's plate: 12 × 12 cubic
    # cells measured 7.5e-5 (clamped) and 1.9e-5 (pinned) from the closed forms; 1e-3
    D = 1e4 * 0.01 ** 3 / (12 * (1 - 0.3 ** 2))
    text = DISC.replace('"clamped"', f'"{edge}"') + SHELL
    model = _built(folder, "disc", text).model
    centre = model.static(LOAD).displacement(0.5, 0.5)[2]
    assert abs(centre / (closed_form * A ** 4 / (64 * D)) - 1) < 1e-3


@pytest.mark.parametrize("tail, rigidity", [
    (SHELL, 1e4 * 0.01 ** 3 / (12 * (1 - 0.3 ** 2))),    # D = E t³/(12(1 − ν²))
    (PLATE.replace("w02 = 1.0", 'w02 = 1.0\nphysics = "intrinsic"'), 1.0),
])
def test_a_disc_face_runs_end_to_end_as_shell_and_intrinsic_plate(folder, tail, rigidity):
    # `splinedeform run` of the face clamped on its loop (12 × 12 cubic cells): the
    # report's largest displacement is the centre deflection q a⁴/(64 D) (the shell
    # 7.5e-5 from it, the intrinsic plate 2.9e-5); 1e-3. The written mesh keeps to the
    # disc: every vertex within the radius, to the file's circle's fit (degree-9 Bézier
    # pieces within 1e-10 of the box's diagonal √2: 2e-10)
    import json

    scenario = folder / "run.toml"
    scenario.write_text(DISC + tail + '[output]\nformats = ["report", "obj"]\n'
                        "resolution = 41\n")
    out = folder / "run-out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the plane is an unbounded surface
        result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    peak = json.loads((out / "report.json").read_text())["solver"]["max displacement"]
    assert abs(peak / (A ** 4 / (64 * rigidity)) - 1) < 1e-3
    vertices = np.array([[float(x) for x in line.split()[1:]]
                         for line in (out / "run.obj").read_text().splitlines()
                         if line.startswith("v ")])
    assert np.hypot(vertices[:, 0] - 0.5, vertices[:, 1] - 0.5).max() < A + 2e-10


def test_a_clamped_disc_face_against_the_same_disc_by_hand(folder):
    # the same discrete problem (B-splines, cells, Nitsche's terms, condition) but for the
    # loop: the file's circle is degree-9 Bézier pieces within 1e-10 of the box's diagonal,
    # the hand's the exact circle, and the cut-cell and loop rules (n + 2 = 5 Gauss points
    # per piece) integrate the two with different errors: measured 6.7e-10 (1.4e-8 on
    # 8 × 8 cells, falling with the pieces' length as a quadrature error does); 1e-8
    g = np.linspace(0.1, 0.9, 17)
    u, v = (x.ravel() for x in np.meshgrid(g, g))
    inside = np.hypot(u - 0.5, v - 0.5) < 0.45
    cad = _static(folder, "disc", DISC + PLATE).displacement(u[inside], v[inside])[..., 2]
    hand = _static(folder, "hand", HAND + PLATE).displacement(u[inside], v[inside])[..., 2]
    assert np.abs(cad - hand).max() < 1e-8 * np.abs(hand).max()


def _strip(u, v, pinned=(0, 2)):
    """``d = q s (W − s) / (2 T)``: the membrane strip between the square's sides
    ``pinned`` (opposite), ``s`` the distance from the first, ``W`` their distance."""
    a, b = (np.array(CORNERS[k]) for k in (pinned[0], (pinned[0] + 1) % 4))
    t = (b - a) / np.linalg.norm(b - a)
    s = (u - a[0]) * -t[1] + (v - a[1]) * t[0]
    width = np.linalg.norm(np.array(CORNERS[1]) - np.array(CORNERS[0]))
    return s * (width - s) / 2


@pytest.mark.parametrize("pinned", [(0, 2), (1, 3)])
def test_opposite_trim_edges_pinned_hold_the_strip(folder, pinned):
    # tension T = 1 under q = 1, pinned on two opposite sides and free on the others: the
    # strip's parabola across the pinned sides, a quadratic the cubic B-splines hold, so
    # Nitsche's method (consistent) and the extension (exact for polynomials) give it but
    # for round-off (measured 1.4e-12 of the sag); 1e-9
    loops = "\n".join(f'outer.{k} = "pinned"' for k in pinned)
    solution = _static(folder, "square", SQUARE.format(loops=loops))
    g = np.linspace(0.05, 0.95, 19)
    u, v = (x.ravel() for x in np.meshgrid(g, g))
    inside = np.abs(u - 0.5) + np.abs(v - 0.5) < 0.49
    d = solution.displacement(u[inside], v[inside])[..., 2]
    exact = _strip(u[inside], v[inside], pinned)
    assert np.abs(d - exact).max() < 1e-9 * exact.max()
    assert exact.max() == pytest.approx(0.0625, rel=1e-12)   # W²/8, W = 1/√2


def test_every_trim_edge_named_is_the_loop_held(folder):
    # the loop's preset and its four edges' are the same boundary terms point by point,
    # summed in another grouping: round-off (measured 0; 1e-12 of the sag)
    edges = "\n".join(f'outer.{k} = "pinned"' for k in range(4))
    whole = _static(folder, "square", SQUARE.format(loops='outer = "pinned"'))
    split = _static(folder, "square", SQUARE.format(loops=edges))
    g = np.linspace(0.2, 0.8, 7)
    a, b = whole.displacement(g, g)[:, 2], split.displacement(g, g)[:, 2]
    assert np.abs(a - b).max() < 1e-12 * np.abs(a).max()


@pytest.mark.parametrize("loops, key, says", [
    ('hole1 = "clamped"', "boundary.loops.hole1", "no loop 'hole1'"),
    ('outer.4 = "pinned"', "boundary.loops.outer.4", "4 trim edge(s), numbered 0 to 3"),
    ('outer = "glued"', "boundary.loops.outer", "glued"),
])
def test_a_loop_the_face_has_not_is_located(folder, loops, key, says):
    with pytest.raises(ScenarioError) as error:
        _built(folder, "square", SQUARE.format(loops=loops))
    assert key in str(error.value) and says in str(error.value)


def test_loops_given_by_hand_or_a_whole_face_take_no_boundary_loops(folder):
    hand = HAND.replace('edge = "clamped"', "") + '[boundary.loops]\nouter = "clamped"\n'
    with pytest.raises(ScenarioError, match=r"boundary\.loops.*\[\[surface\.trim\.loops\]\]"):
        _built(folder, "hand", hand + PLATE)
    whole = SQUARE.format(loops='outer = "pinned"').replace("trimmed = true",
                                                            "trimmed = false")
    with pytest.raises(ScenarioError, match=r"boundary\.loops.*whole surface"):
        _built(folder, "square", whole)


def test_faces_lists_the_loop_names(folder):
    result = CliRunner().invoke(cli.app, ["faces", str(folder / "square.step")])
    assert result.exit_code == 0, result.output
    assert "face 0 loops: outer (4 trim edges, outer.0 … outer.3)" in result.output
    result = CliRunner().invoke(cli.app, ["faces", str(folder / "disc.3dm"), "--json"])
    assert result.exit_code == 0, result.output
    assert '"loop_names": {\n        "outer": 1\n      }' in result.output
