"""Bodies of CAD faces run from scenarios and the command line (scenario/body.py,
pipeline_body.py, outputs_body.py): a 2 × 2 × 2 box of six faces in inches, built here
with rhino3dm, under internal pressure with membrane tension."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
meshio = pytest.importorskip("meshio")

from splinedeform.cad_body import read_body  # noqa: E402

runner = CliRunner()
SIZE = 2.0


@pytest.fixture(scope="module")
def box_3dm(tmp_path_factory):
    """A closed 2 × 2 × 2 box of six bilinear faces (object "box"), in inches."""
    path = tmp_path_factory.mktemp("bodyrun") / "box.3dm"
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = r3.UnitSystem.Inches
    attributes = r3.ObjectAttributes()
    attributes.Name = "box"
    model.Objects.AddBrep(r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, SIZE, SIZE,
                                                                      SIZE))), attributes)
    assert model.Write(str(path), 7)
    return path


def write_scenario(folder, source, extra="", solve='kind = "static"\nframes = 3',
                   formats='["vtu", "obj", "3dm", "step", "images", "report"]', loads=None):
    """A scenario of every face of ``source`` (copied beside it): ``faces`` left to its
    default, tension in both directions, an internal pressure unless ``loads`` is given."""
    import shutil

    shutil.copy(source, folder / source.name)
    loads = '[[load]]\nkind = "pressure"\nq = 0.5\n' if loads is None else loads
    path = folder / "box.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{source.name}"\n{extra}\n'
                    '[material]\nw10 = 1.0\nw01 = 1.0\n'
                    f'{loads}[solve]\n{solve}\n[output]\nformats = {formats}\n'
                    'resolution = 9\n')
    return path


def grid_of(srf, n=9):
    """Points of a rhino3dm surface on an ``n × n`` grid of its own domain."""
    u = np.linspace(srf.Domain(0).T0, srf.Domain(0).T1, n)
    v = np.linspace(srf.Domain(1).T0, srf.Domain(1).T1, n)
    return np.array([[[p.X, p.Y, p.Z] for p in (srf.PointAt(a, b) for b in v)] for a in u])


def edge_of(grid, edge):
    """The side ``edge`` ("u0", "u1", "v0", "v1") of a sampled grid ``(n, n, 3)``."""
    return {"u0": grid[0], "u1": grid[-1], "v0": grid[:, 0], "v1": grid[:, -1]}[edge]


def test_a_closed_box_under_internal_pressure_runs_from_the_command_line(box_3dm, tmp_path):
    scenario = write_scenario(tmp_path, box_3dm)
    result = runner.invoke(cli.app, ["validate", str(scenario)])
    assert result.exit_code == 0, result.output
    assert "6 (0, 1, 2, 3, 4, 5)" in result.output and "12 shared" in result.output
    out = tmp_path / "out"
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output

    report = json.loads((out / "report.json").read_text())
    body = report["body"]
    assert body["units"] == "in" and body["faces"] == [0, 1, 2, 3, 4, 5]
    assert body["topology"]["shared"] == 12 and body["topology"]["boundary"] == 0
    assert body["patches"] == 6 and body["interfaces"] == 12

    # the deformed body read back by rhino3dm: in inches, one closed Brep of six named
    # faces, its edges joined
    written = r3.File3dm.Read(str(out / "box.3dm"))
    assert str(written.Settings.ModelUnitSystem).endswith("Inches")
    (brep,) = list(written.Objects)
    assert brep.Attributes.Name == "box" and [brep.Attributes.GetUserString(
        f"splinedeform.face {k}") for k in range(6)] == [f"box face {k}" for k in range(6)]
    assert brep.Geometry.IsValid and brep.Geometry.IsSolid and len(brep.Geometry.Edges) == 12
    deformed = [grid_of(face.UnderlyingSurface()) for face in brep.Geometry.Faces]
    source = r3.File3dm.Read(str(box_3dm))
    rest = [grid_of(face.UnderlyingSurface()) for o in source.Objects
            for face in o.Geometry.Faces]

    # closed: along each of the box's edges the two deformed faces are one curve
    # (merged control points evaluated by openNURBS: 1e-12 of the size)
    _, topology, _ = read_body(box_3dm)
    assert len(topology.interfaces) == 12
    for i in topology.interfaces:
        a, b = edge_of(deformed[i.a], i.edge_a), edge_of(deformed[i.b], i.edge_b)
        gap = np.abs(a - (b[::-1] if i.reversed else b)).max()
        assert gap < 1e-12 * SIZE, (i, gap)

    # symmetric: the six faces move alike (round-off of one sparse solve: 1e-10 relative)
    largest = [np.linalg.norm(d - r, axis=-1).max() for d, r in zip(deformed, rest)]
    assert np.ptp(largest) <= 1e-10 * max(largest) and min(largest) > 0
    centres = [report["probes"][f"face {k} centre magnitude"][-1] for k in range(6)]
    assert np.ptp(centres) <= 1e-10 * max(centres)
    # and outwards: each face's centre moves away from the box's centre
    for d, r in zip(deformed, rest):
        centre = r[4, 4]
        assert np.dot(d[4, 4] - centre, centre - SIZE / 2) > 0

    # the welded mesh of the last frame is watertight: every triangle edge on two triangles
    mesh = meshio.read(out / "box.obj")
    triangles = mesh.cells_dict["triangle"]
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                    triangles[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert set(counts.tolist()) == {2}
    r = 9                                   # six r × r grids welded along 12 edges, 8 corners
    assert len(mesh.points) == 6 * r * r - 12 * r + 8
    # the series: one welded .vtu per frame, the last one the obj's points (both written
    # from the same samples: 1e-12 of the size for the text of the .obj)
    series = meshio.read(out / "box_0002.vtu")
    np.testing.assert_allclose(np.sort(series.points + series.point_data["displacement"],
                                       axis=0),
                               np.sort(mesh.points, axis=0), rtol=0, atol=1e-12 * SIZE)
    assert (out / "surfaces.png").stat().st_size > 0 and (out / "box.step").exists()


def test_the_step_output_is_the_body_in_its_unit(box_3dm, tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    scenario = load_scenario(write_scenario(tmp_path, box_3dm, formats='["step"]'))
    result = run(scenario, tmp_path / "out")
    surfaces, topology, info = read_body(tmp_path / "out" / "box.step")
    assert info["units"] == "in" and topology.counts["shared"] == 12
    # the written nets are the solution's last frame (STEP written and read back: two
    # roundings of a product by 25.4, 1e-12 of the size)
    read = sorted(s.control_points.reshape(-1, 3).round(9).tolist() for s in surfaces)
    want = sorted(n[-1].reshape(-1, 3).round(9).tolist() for n in result.nets)
    np.testing.assert_allclose(np.array(read), np.array(want), rtol=0, atol=1e-12 * SIZE * 4)


def test_modes_and_the_closed_form_dynamics_of_a_body(box_3dm, tmp_path):
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    modes = load_scenario(write_scenario(tmp_path, box_3dm, solve='kind = "modes"\nmodes = 4'
                                         '\nframes = 3', formats='["report"]', loads=""))
    result = run(modes, tmp_path / "modes")
    # a free body: the lowest mode is its translation (ω = 0 to round-off of the largest
    # ω, 1e-6 of it)
    assert result.omegas[0] <= 1e-6 * result.omegas[-1]
    assert len(result.nets) == 6 and result.nets[0].shape == (3, 2, 2, 3)
    dynamic = load_scenario(write_scenario(
        tmp_path, box_3dm, solve='kind = "dynamic"\nt_end = 1.0\nframes = 3\nmodes = 0',
        formats='["vtu", "images", "report"]'))
    result = run(dynamic, tmp_path / "dynamic")
    assert (tmp_path / "dynamic" / "probes.png").exists()
    # the energy of the undamped response under a constant load is conserved (the
    # closed form: round-off, 1e-9 of the work)
    total, work = result.energy["total"], result.energy["work"]
    assert np.abs(total - total[0]).max() <= 1e-9 * np.abs(work).max()


def test_a_point_load_names_its_face(box_3dm, tmp_path):
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    push = '[[load]]\nkind = "point"\nat = [0.5, 0.5]\nface = 3\nforce = [0, 0, 1.0]\n'
    scenario = load_scenario(write_scenario(tmp_path, box_3dm, formats='["report"]',
                                            loads=push + '[[load]]\nkind = "point"\n'
                                            'at = [0.5, 0.5]\nface = 2\nforce = [0, 0, -1.0]\n'))
    result = run(scenario, tmp_path / "out")
    # each force works through the displacement of its own face at its own parameters:
    # the work of the reduced load vectors equals f · d(0.5, 0.5) summed over the two
    # faces, evaluated on the deformed patches (round-off: 1e-12 of the work)
    f = np.array([0, 0, 1.0])
    d3, d2 = (result.solution.displacement(0.5, 0.5, patch=k) for k in (3, 2))
    work = float(f @ d3 - f @ d2)
    assert work > 0
    assert result.energy["work"] == pytest.approx(work, rel=1e-12)


def refusal(folder, source, **kwargs) -> str:
    from splinedeform.errors import ScenarioError
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    with pytest.raises(ScenarioError) as info:
        run(load_scenario(write_scenario(folder, source, **kwargs)), folder / "out")
    return str(info.value)


def test_what_a_body_does_not_take_is_refused_at_its_key(box_3dm, tmp_path):
    message = refusal(tmp_path, box_3dm, formats='["report"]',
                      loads='[[load]]\nkind = "point"\nat = [0.5, 0.5]\nforce = [0, 0, 1.0]\n')
    assert "load[1].face: a point load on a body names its face" in message
    message = refusal(tmp_path, box_3dm, formats='["report"]',
                      loads='[[load]]\nkind = "pressure"\nq = 1.0\nface = 9\n')
    assert "load[1].face: face 9 is not in this body, whose faces are [0, 1, 2, 3, 4, 5]" \
        in message
    message = refusal(tmp_path, box_3dm, formats='["report"]',
                      extra='[boundary]\nu0 = "pinned"')
    assert "boundary: a body takes one preset for every boundary edge" in message


def test_a_single_face_file_runs_as_one_surface(tmp_path):
    """faces = "all" is the default: a file of one face is read as `face = 0` is."""
    from splinedeform.cad import NurbsPatch, write_3dm
    from splinedeform.scenario import build, load_scenario
    from splinedeform.surface import Surface

    knots = np.array([0, 0, 0, 1, 1, 1.0])
    x, y = np.meshgrid([0, 0.5, 1], [0, 0.5, 1], indexing="ij")
    (tmp_path / "src").mkdir()
    path = write_3dm(tmp_path / "src" / "one.3dm", [NurbsPatch(
        (2, 2), knots, knots, np.stack([x, y, 0 * x], -1), np.ones((3, 3)))])
    default = build(load_scenario(write_scenario(tmp_path, path, formats='["report"]',
                                                 extra='[boundary]\nu0 = "pinned"\n'
                                                       'u1 = "pinned"')))
    assert isinstance(default.surface, Surface)
    (tmp_path / "box.toml").write_text((tmp_path / "box.toml").read_text().replace(
        'path = "one.3dm"', 'path = "one.3dm"\nface = 0'))
    one = build(load_scenario(tmp_path / "box.toml"))
    # the same face read by the same reader twice: the same numbers
    np.testing.assert_allclose(default.surface.control_points, one.surface.control_points,
                               rtol=1e-15, atol=0)
    assert default.model.n_free == one.model.n_free


def test_a_body_scenario_is_written_back_as_it_runs(box_3dm, tmp_path):
    """The scenario written into a report reads back as the same body: every face (no
    `face = 0`) and each load's face."""
    from splinedeform.scenario import parse_scenario, scenario_to_toml

    push = '[[load]]\nkind = "point"\nat = [0.5, 0.5]\nface = 2\nforce = [0, 0, 1.0]\n'
    path = write_scenario(tmp_path, box_3dm, formats='["report"]', loads=push)
    scenario = parse_scenario(path.read_text(), directory=tmp_path)
    text = scenario_to_toml(scenario)
    assert "face = 2" in text and "face = 0" not in text
    again = parse_scenario(text, directory=tmp_path)
    assert again.loads == scenario.loads and again.surface == scenario.surface
    assert "face" not in again.raw["surface"]


def test_control_nets_and_the_animation_hold_every_face(box_3dm, tmp_path):
    """json / npz hold every face's nets keyed by face number; the GIF (and MP4 where an
    encoder is installed) draws the whole body in every frame."""
    from PIL import Image

    from splinedeform.export.body_nets import read_body_control_nets
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario
    from splinedeform.viz import mp4_available

    formats = ["json", "npz", "gif"] + (["mp4"] if mp4_available() else [])
    scenario = load_scenario(write_scenario(tmp_path, box_3dm, formats=json.dumps(formats)))
    out = tmp_path / "out"
    result = run(scenario, out)
    # read by the standard library and numpy alone: every face, every frame. JSON floats
    # are written with repr and the NPZ holds the arrays themselves, so both give the
    # solution's numbers back (to the last bit; compared at 1e-15 relative)
    document = json.loads((out / "box_nets.json").read_text())
    assert document["faces"] == [0, 1, 2, 3, 4, 5] and len(document["times"]) == 3
    arrays = np.load(out / "box_nets.npz")
    assert list(arrays["faces"]) == [0, 1, 2, 3, 4, 5]
    for k, nets in enumerate(result.nets):
        np.testing.assert_allclose(document["nets"][str(k)]["control_points"], nets,
                                   rtol=1e-15, atol=0)
        np.testing.assert_allclose(arrays[f"face{k}/control_points"], nets, rtol=1e-15,
                                   atol=0)
        assert document["nets"][str(k)]["basis"]["u"]["knots"] == \
            arrays[f"face{k}/knots_u"].tolist()
    # read back as surfaces: each face at the last frame is the deformed patch (the same
    # bases and net evaluated twice: round-off, 1e-12 of the size)
    for path in (out / "box_nets.json", out / "box_nets.npz"):
        faces = read_body_control_nets(path)
        for k, patch in enumerate(result.built.surface.patches):
            deformed = patch.with_control_points(result.nets[k][-1])
            s = np.linspace(0.0, 1.0, 5)
            np.testing.assert_allclose(faces[k].evaluate(s[:, None], s[None, :]),
                                       deformed.evaluate(s[:, None], s[None, :]),
                                       rtol=0, atol=1e-12 * SIZE)
    with Image.open(out / "box.gif") as gif:
        assert gif.n_frames == 3 and gif.size == (640, 480)
    if "mp4" in formats:
        assert (out / "box.mp4").stat().st_size > 0
