"""Refinement and per-face boundary conditions of bodies from scenarios (scenario/body.py):
the 2 × 2 × 2 box of six bilinear faces that tests/test_body_run.py builds with rhino3dm,
elevated to cubic and refined, bending under internal pressure; an open box (five faces)
held by one edge."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

# the 2 × 2 × 2 box (in inches) and the sampling of a .3dm read back
from test_body_run import SIZE, box_3dm, edge_of, grid_of  # noqa: E402,F401

runner = CliRunner()
PLATE = "[material]\nw10 = 1.0\nw01 = 1.0\nw20 = 1.0\nw02 = 1.0\n"


def scenario_file(folder, source, surface="", boundary="", formats='["report"]'):
    """A plate scenario (tension and bending) of ``source`` (copied beside it) under an
    internal pressure; ``surface`` and ``boundary`` are lines of those tables."""
    import shutil

    shutil.copy(source, folder / source.name)
    path = folder / "body.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{source.name}"\n{surface}\n{PLATE}'
                    f'[boundary]\n{boundary}\n[[load]]\nkind = "pressure"\nq = 0.5\n'
                    f'[solve]\nkind = "static"\nframes = 2\n[output]\nformats = {formats}\n'
                    'resolution = 9\n')
    return path


def built_surface(path):
    from splinedeform.scenario import load_scenario
    from splinedeform.scenario.build import surface_and_units

    return surface_and_units(load_scenario(path))[0]


def sample(surface, n=13):
    u = np.linspace(0.0, surface.basis_u.length, n)
    v = np.linspace(0.0, surface.basis_v.length, n)
    return surface.evaluate(u[:, None], v[None, :])


def test_refinement_of_a_body_keeps_its_geometry_and_its_conforming_edges(box_3dm, tmp_path):
    from splinedeform.body import Body

    rest = built_surface(scenario_file(tmp_path, box_3dm))
    fine = built_surface(scenario_file(tmp_path, box_3dm, "elevate = 2\nrefine = 2"))
    assert len(fine) == 6
    for coarse, refined in zip(rest, fine):
        assert (refined.basis_u.degree, refined.basis_v.degree) == (3, 3)
        assert refined.shape == (6, 6)     # degree 3, 3 spans: 3 + 3 functions
        # exact knot insertion and degree elevation: the same surface up to round-off of
        # the refinement matrices (1e-12 of the size)
        np.testing.assert_allclose(sample(refined), sample(coarse), rtol=0,
                                   atol=1e-12 * SIZE)
    # the file's interfaces still conform on the refined faces, and so does every
    # interface found again from the geometry alone (an independent matching)
    assert len(fine.interfaces) == 12 and all(i.conforming for i in fine.interfaces)
    found = Body.from_surfaces(list(fine)).summary()
    assert found["shared"] == 12 and found["non_conforming"] == 0 and found["boundary"] == 0


@pytest.mark.parametrize("surface", ["refine = {u = 1, v = 2}", "elevate = [1, 0]",
                                     "elevate = [2, 1]\nrefine = [0, 3]"])
def test_different_counts_in_u_and_v_are_repaired_on_a_body(box_3dm, tmp_path, surface):
    """A box edge is a u edge of one face and a v edge of its neighbour: counts that differ
    in u and v are repaired by exact elevation and knot insertion (scenario/body.py)."""
    from splinedeform.body import Body

    rest = built_surface(scenario_file(tmp_path, box_3dm))
    fine = built_surface(scenario_file(tmp_path, box_3dm, surface))
    for coarse, refined in zip(rest, fine):
        # exact refinement: the same surface up to round-off of the refinement matrices
        # (1e-12 of the size)
        np.testing.assert_allclose(sample(refined), sample(coarse), rtol=0,
                                   atol=1e-12 * SIZE)
    # every file interface conforms on the refined faces (merged, not penalised), and so
    # does every interface found again from the geometry alone (an independent matching)
    assert len(fine.interfaces) == 12 and all(i.conforming for i in fine.interfaces)
    found = Body.from_surfaces(list(fine)).summary()
    assert found["shared"] == 12 and found["non_conforming"] == 0
    # at least the counts asked for: each face has at least the degree and spans it asked
    elevate = {"refine = {u = 1, v = 2}": (0, 0), "elevate = [1, 0]": (1, 0)}.get(surface,
                                                                                    (2, 1))
    for coarse, refined in zip(rest, fine):
        assert refined.basis_u.degree >= coarse.basis_u.degree + elevate[0]
        assert refined.basis_v.degree >= coarse.basis_v.degree + elevate[1]


def test_a_cubic_box_bends_under_internal_pressure_closed_and_symmetric(box_3dm, tmp_path):
    scenario = scenario_file(tmp_path, box_3dm, "elevate = 2\nrefine = 2",
                             formats='["3dm", "report"]')
    out = tmp_path / "out"
    result = runner.invoke(cli.app, ["run", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["body"]["degrees"] == [[3, 3]] * 6
    assert report["body"]["nets"] == ["6 x 6"] * 6

    written = r3.File3dm.Read(str(out / "body.3dm"))       # one Brep, a face per patch
    deformed = [grid_of(face.UnderlyingSurface()) for o in written.Objects
                for face in o.Geometry.Faces]
    assert len(deformed) == 6 and written.Objects[0].Geometry.IsSolid
    source = r3.File3dm.Read(str(box_3dm))
    rest = [grid_of(face.UnderlyingSurface()) for o in source.Objects
            for face in o.Geometry.Faces]
    from splinedeform.cad_body import read_body

    _, topology, _ = read_body(box_3dm)
    # closed: the merged control points of each edge evaluated by openNURBS on both faces
    # (round-off of two evaluations, far below 1e-10 of the size)
    for i in topology.interfaces:
        a, b = edge_of(deformed[i.a], i.edge_a), edge_of(deformed[i.b], i.edge_b)
        gap = np.abs(a - (b[::-1] if i.reversed else b)).max()
        assert gap < 1e-10 * SIZE, (i, gap)
    # symmetric: the six faces' largest displacements agree to 1e-8 relative. The solve is
    # one sparse factorisation whose conditioning the penalty coupling of the rotations
    # across the edges raises (factors of the bending weight over the mesh size), so
    # round-off reaches about 1e-10 here; 1e-8 leaves room for another BLAS, and is far
    # below any asymmetry a wrong face orientation or coupling would cause (order 1)
    largest = [np.linalg.norm(d - r, axis=-1).max() for d, r in zip(deformed, rest)]
    assert min(largest) > 0.01 * SIZE
    assert np.ptp(largest) <= 1e-8 * max(largest)
    # and outwards: each face's centre moves away from the box's centre
    for d, r in zip(deformed, rest):
        centre = r[4, 4]
        assert np.dot(d[4, 4] - centre, centre - SIZE / 2) > 0


def open_box(folder, source, boundary):
    """The box without its top (faces 0 to 4: four walls and the bottom)."""
    return scenario_file(folder, source, "faces = [0, 1, 2, 3, 4]\nelevate = 1\nrefine = 1",
                         boundary)


def test_one_face_edge_clamped_holds_an_open_box(box_3dm, tmp_path):
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    body = built_surface(open_box(tmp_path, box_3dm, ""))
    rim = body.topology.boundary              # the four walls' top edges
    assert len(rim) == 4
    patch, edge = rim[0]
    face = body.faces[patch]
    held = run(load_scenario(open_box(tmp_path, box_3dm, f'[boundary.faces]\n{face} = '
                                      f'{{{edge} = "clamped"}}\n')), tmp_path / "one")
    surface = body[patch]
    s = np.linspace(0.0, 1.0, 7)
    u, v = {"u0": (0 * s, s), "u1": (0 * s + 1, s), "v0": (s, 0 * s),
            "v1": (s, 0 * s + 1)}[edge]
    u, v = u * surface.basis_u.length, v * surface.basis_v.length
    on_edge = np.array([held.solution.displacement(a, b, patch=patch) for a, b in zip(u, v)])
    # the clamped edge does not move (its control points are fixed: round-off of the
    # evaluation, 1e-14 of the size), while the body does
    assert np.abs(on_edge).max() <= 1e-14 * SIZE
    middle = held.solution.displacement(surface.basis_u.length / 2,
                                        surface.basis_v.length / 2, patch=patch)
    assert np.linalg.norm(middle) > 1e-3 * SIZE
    # every rim edge named face by face is the one preset for all boundary edges: two
    # ways of building the same constraint map, the same solve (round-off: 1e-10 relative)
    each = "".join(f'{body.faces[p]} = {{{e} = "clamped"}}\n' for p, e in rim)
    named = run(load_scenario(open_box(tmp_path, box_3dm, f"[boundary.faces]\n{each}")),
                tmp_path / "named")
    preset = run(load_scenario(open_box(tmp_path, box_3dm, 'u0 = "clamped"\nu1 = "clamped"\n'
                                        'v0 = "clamped"\nv1 = "clamped"\n')),
                 tmp_path / "preset")
    a = np.concatenate([n[-1].ravel() for n in named.nets])
    b = np.concatenate([n[-1].ravel() for n in preset.nets])
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * np.abs(b).max())


def test_face_edges_are_checked_at_their_key(box_3dm, tmp_path):
    from splinedeform.errors import ScenarioError
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    def refusal(boundary):
        with pytest.raises(ScenarioError) as info:
            run(load_scenario(open_box(tmp_path, box_3dm, boundary)), tmp_path / "out")
        return str(info.value)

    body = built_surface(open_box(tmp_path, box_3dm, ""))
    joined = body.interfaces[0]
    face, edge = body.faces[joined.a], joined.edge_a
    message = refusal(f'[boundary.faces]\n{face} = {{{joined.edge_a} = "pinned"}}\n')
    assert (f"boundary.faces.{face}.{edge}: edge {edge} of face {face} is an interface (it "
            f"meets edge {joined.edge_b} of face {body.faces[joined.b]})") in message
    assert "boundary.faces.5: face 5 is not in this body, whose faces are [0, 1, 2, 3, 4]" \
        in refusal('[boundary.faces]\n5 = {u0 = "clamped"}\n')
    assert ("boundary.faces.0.u0: 'diaphragm' is an edge of the Kirchhoff–Love shell only"
            in refusal('[boundary.faces]\n0 = {u0 = "diaphragm"}\n'))
    assert "boundary.faces.0.u0: Input should be 'free', 'pinned'" \
        in refusal('[boundary.faces]\n0 = {u0 = "hinged"}\n')
    assert "boundary.faces.0.w0" in refusal('[boundary.faces]\n0 = {w0 = "clamped"}\n')
    # one face read alone is not a body: the key is refused there
    single = scenario_file(tmp_path, box_3dm, "face = 0\nelevate = 1",
                           '[boundary.faces]\n0 = {u0 = "clamped"}\n')
    with pytest.raises(ScenarioError) as info:
        run(load_scenario(single), tmp_path / "single")
    assert "boundary.faces: names edges of the faces of a body of CAD faces" in str(info.value)
