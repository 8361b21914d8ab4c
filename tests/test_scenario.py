"""Scenario files: parsing, validation messages (file, key path, line), printing, building."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from splinedeform import BSplineBasis, Surface
from splinedeform.errors import InputError, ScenarioError
from splinedeform.scenario import (SHAPE_PARAMETERS, Scenario, build, build_load, describe,
                                   documented_keys, free_region_mask, key_lines, load_scenario,
                                   parse_scenario, scenario_to_toml, with_overrides)

from tiny_scenario import BASE
from trim_scenario import TRIMMED

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "scenario.md"

# -- scenarios that together use every documented key ----------------------------------
PLANE = """
title = "membrane square"
description = "a square membrane under a centred point force"

[surface]
shape = "plane"
size = [2.0, 1.0]
cells = [4, 3]
degree = 2
knots = "open"
method = "interpolate"

[material]
mass = 2.0
damping = 0.5
rayleigh = 0.01
w10 = 1.0
w01 = 1.5
w20 = 0.0
w11 = 0.0
w02 = 0.0
mass_matrix = "lumped"
physics = "parametric"

[boundary]
u0 = "clamped"
u1 = "pinned"
v0 = "pinned"
v1 = "free"
free_region = { u = [0.2, 1.8], v = [0.0, 0.9] }

[[load]]
kind = "point"
at = [1.0, 0.5]
force = [0.0, 0.0, -1.0]
profile = "step"
t_on = 0.1
t_off = 0.5

[[load]]
kind = "uniform"
force = [0.0, 0.0, -0.1]
profile = "piecewise"
points = [[0.0, 1.0],
          [0.3, 0.5]]   # a multi-line array

[[load]]
kind = "pressure"
q = 0.2
profile = "harmonic"
omega = 3.0
phase = 0.5

[solve]
kind = "dynamic"
method = "rk45"
t_end = 1.0
frames = 5
modes = 3
rtol = 1e-6
atol = 1e-9

[output]
formats = ["obj", "report"]
resolution = 8
probes = [[1.0, 0.5], [0.5, 0.25]]
time = 0.5
"""

NEWMARK = """
[surface]
shape = "plane"
cells = 3
[material]
w20 = 1.0
w11 = 1.0
w02 = 1.0
[boundary]
u0 = "clamped"
u1 = "clamped"
v0 = "clamped"
v1 = "clamped"
[[load]]
kind = "uniform"
force = [0, 0, 1]
[solve]
kind = "dynamic"
method = "newmark"
times = [0.0, 0.25, 1.0]
dt = 0.01
"""

MODES = """
[surface]
shape = "plane"
cells = 3
[material]
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"
[solve]
kind = "modes"
modes = 4
frames = 6
"""

STATIC = """
[surface]
shape = "plane"
cells = 3
[material]
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"
[[load]]
kind = "uniform"
force = [0, 0, -1]
[solve]
kind = "static"
"""

ANALYTIC = (BASE
            .replace('profile = "step"', 'profile = "piecewise"\npoints = [[0.0, 1.0], [0.5, 0.0]]')
            .replace("t_end = 2.0\nframes = 5",
                     'method = "analytic"\nt_end = 1.0\nframes = 3\nfunction_samples = 64'))

#: the free set listed point by point, as splinedeform sculpt paints it
PAINTED = STATIC.replace('v1 = "pinned"\n', 'v1 = "pinned"\nfree_points = [[1, 1], [2, 2], [3, 3]]\n')

COVERAGE = {"plane": PLANE, "newmark": NEWMARK, "modes": MODES, "static": STATIC,
            "analytic": ANALYTIC, "painted": PAINTED, "trimmed": TRIMMED}


def shape_scenario(shape: str, params: dict[str, object]) -> str:
    """A minimal modes scenario of a built-in shape with the given shape parameters."""
    lines = [f"{k} = {v!r}".replace("'", '"').replace("(", "[").replace(")", "]")
             for k, v in params.items()]
    return "\n".join(["[surface]", f'shape = "{shape}"', "cells = 4", *lines,
                      "[material]", "w10 = 1.0", "w01 = 1.0",
                      "[solve]", 'kind = "modes"', "modes = 2"]) + "\n"


def file_scenario(path: str, extra: str = "") -> str:
    return (f'[surface]\nshape = "file"\npath = "{path}"\n{extra}\n'
            '[material]\nw10 = 1.0\nw01 = 1.0\n[solve]\nkind = "modes"\nmodes = 2\n')


SHAPE_TEXTS = {shape: shape_scenario(shape, {k: key.default for k, key in params.items()})
               for shape, params in SHAPE_PARAMETERS.items() if shape not in ("file", "cad")}
FILE_TEXTS = [file_scenario("net.json", "frame = 0"),
              file_scenario("grid.npy", 'cells = 3\ndegree = 2\nknots = ["open", "open"]\n'
                                        'method = "l2"'),
              file_scenario("patch.3dm", 'face = 1\nunits = "in"\nrefine = {u = 2, v = 1}\n'
                                         'elevate = [0, 1]').replace('"file"', '"cad"'),
              # several faces of a CAD file: run by tests/test_cad_body.py on files built there
              file_scenario("solids.3dm", 'faces = ["box"]').replace('"file"', '"cad"'),
              # a load on one face of a body: run by tests/test_body_run.py
              file_scenario("box.3dm", "").replace('"file"', '"cad"')
              + '[[load]]\nkind = "pressure"\nq = 1.0\nface = 2\n',
              # an edge of a body's face clamped: run by tests/test_body_refine_run.py
              file_scenario("box.3dm", 'faces = [0, 1, 2, 3, 4]').replace('"file"', '"cad"')
              + '[boundary.faces]\n0 = { v1 = "clamped" }\n',
              # the moving control points of one face of a body: run by
              # tests/test_body_free_points.py
              file_scenario("two.3dm", "").replace('"file"', '"cad"')
              + '[boundary.faces_free_points]\n0 = [[2, 2], [2, 3]]\n',
              # probes on named faces of a body: run by tests/test_body_shell_run.py
              file_scenario("roof.3dm", "").replace('"file"', '"cad"')
              + '[output]\nprobes = [[0.0, 25.0]]\nprobe_faces = [0]\n',
              # a trimmed face on its trimmed region: run by tests/test_cad_trim_run.py
              file_scenario("planes.3dm", 'trimmed = true').replace('"file"', '"cad"'),
              # a trimmed face's loops held: run by tests/test_cad_trim_loops.py
              file_scenario("square.step", 'trimmed = true').replace('"file"', '"cad"')
              + '[boundary.loops]\nouter = "pinned"\n']


def all_test_texts() -> list[str]:
    texts = list(COVERAGE.values()) + list(SHAPE_TEXTS.values()) + FILE_TEXTS
    texts += [p.read_text() for p in sorted((ROOT / "examples").glob("*.toml"))]
    texts.append((ROOT / "src/splinedeform/data/demo.toml").read_text())
    return texts


def normalised(path: str) -> str:
    """``load[2].force`` -> ``load.force``; ``output.probes[1]`` -> ``output.probes``."""
    return re.sub(r"\[\d+\]", "", path)


def error_of(text: str, source: str = "case.toml") -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source=source)
    return str(info.value)


# -- the documentation lists every key, and every key is used here ------------------
def documented_in_markdown() -> list[str]:
    rows = re.findall(r"^\|\s*`([A-Za-z0-9_.]+)`\s*\|", DOC.read_text(encoding="utf-8"), re.M)
    assert rows, "docs/scenario.md has no key table"
    return rows


def test_doc_lists_exactly_the_keys_the_reader_accepts():
    doc = documented_in_markdown()
    assert len(doc) == len(set(doc)), "a key is documented twice"
    assert set(doc) == set(documented_keys())


def test_every_documented_key_is_exercised_by_a_test_scenario():
    used = {normalised(path) for text in all_test_texts() for path in key_lines(text)}
    missing = sorted(set(documented_in_markdown()) - used)
    assert not missing, f"documented keys never used in a test scenario: {missing}"


@pytest.mark.parametrize("name", sorted(COVERAGE))
def test_coverage_scenarios_are_valid_and_print_back_identically(name):
    s = parse_scenario(COVERAGE[name], source=f"{name}.toml")
    again = parse_scenario(scenario_to_toml(s), source="printed.toml")
    for part in ("surface", "material", "boundary", "loads", "solve", "output", "title",
                 "description"):
        assert getattr(again, part) == getattr(s, part), part


def test_values_are_read_as_written():
    s = parse_scenario(PLANE)
    assert s.surface.cells == (4, 3) and s.surface.degree == 2
    assert s.surface.knots == "open"
    assert s.surface.parameters == {"size": (2.0, 1.0)}
    assert s.material.mass_matrix == "lumped" and s.material.rayleigh == 0.01
    assert s.boundary.edges() == {"u0": "clamped", "u1": "pinned", "v0": "pinned", "v1": "free"}
    assert s.boundary.free_u == (0.2, 1.8) and s.boundary.free_v == (0.0, 0.9)
    point, uniform, pressure = s.loads
    assert point.at == (1.0, 0.5) and point.force == (0.0, 0.0, -1.0)
    assert (point.t_on, point.t_off) == (0.1, 0.5)
    assert uniform.points == ((0.0, 1.0), (0.3, 0.5))
    assert (pressure.q, pressure.omega, pressure.phase) == (0.2, 3.0, 0.5)
    assert s.solve.frame_times() == (0.0, 0.25, 0.5, 0.75, 1.0)
    assert s.output.probes == ((1.0, 0.5), (0.5, 0.25)) and s.output.time == 0.5


def test_defaults_follow_the_documented_values():
    s = parse_scenario(STATIC)
    assert s.surface.cells == (3, 3) and s.surface.degree == 3 and s.surface.knots is None
    assert parse_scenario(MODES.replace("cells = 3\n", "")).surface.cells is None
    assert s.material.mass == 1.0 and s.material.damping == 0.0
    assert s.loads[0].profile == "constant" and math.isinf(s.loads[0].t_off)
    assert s.solve.frames == 50
    assert s.output.formats == ("report",) and s.output.resolution == 32


def test_times_alone_set_the_end_time():
    s = parse_scenario(NEWMARK)
    assert s.solve.t_end == 1.0 and s.solve.frame_times() == (0.0, 0.25, 1.0)


def test_format_aliases_expand():
    s = parse_scenario(STATIC + '[output]\nformats = ["nets", "pvd", "animation"]\n')
    assert s.output.formats == ("json", "npz", "vtu", "gif")


# -- where keys are written -----------------------------------------------------------------
def test_key_lines_follow_tables_arrays_inline_tables_and_strings():
    text = "\n".join([
        'title = "a [fake] table # not a comment"',    # 1
        "# [surface] in a comment",                      # 2
        "[surface]",                                     # 3
        "  shape = 'plane'  # comment",                  # 4
        '"cells" = [',                                   # 5
        "   2,",                                         # 6
        "   3]",                                         # 7
        "[[load]]",                                      # 8
        "kind = 'point'",                                # 9
        "[[load]]",                                      # 10
        'description = """ line',                        # 11
        "kind = 'fake' inside a string",                 # 12
        '"""',                                           # 13
        "at = [0.5,",                                    # 14
        "      0.25]",                                   # 15
        "[boundary]",                                    # 16
        "free_region = { u = [0, 1],",                   # 17  (TOML 1.0 inline tables are one line;
        "                v = [0, 1] }",                  # 18   the scanner still follows them)
        "surface.degree = 2",                            # 19  dotted key inside [boundary]
    ])
    lines = key_lines(text)
    assert lines["title"] == 1
    assert lines["surface"] == 3 and lines["surface.shape"] == 4
    assert lines["surface.cells"] == 5 and lines["surface.cells[2]"] == 7
    assert lines["load[1]"] == 8 and lines["load[1].kind"] == 9
    assert lines["load[2]"] == 10 and lines["load[2].description"] == 11
    assert "load[2].kind" not in lines
    assert lines["load[2].at"] == 14 and lines["load[2].at[2]"] == 15
    assert lines["boundary.free_region.u"] == 17 and lines["boundary.free_region.v"] == 18
    assert lines["boundary.surface.degree"] == 19


def test_quoted_keys_are_located_by_the_key_they_name():
    # A basic quoted key's escapes name the same key as its bare spelling; a literal
    # quoted key keeps its backslashes. Lines are exact integers: no tolerance.
    text = "\n".join([
        "[material]",                # 1
        '"m\\u0061ss" = 2.0',       # 2  "m\u0061ss" is the key mass
        "'w\\10' = 1.0",            # 3  literal: the key is w\10
    ])
    lines = key_lines(text)
    assert lines["material.mass"] == 2
    assert lines["material.w\\10"] == 3


def test_an_unknown_escaped_key_is_reported_at_its_own_line():
    text = PLANE.replace("mass = 2.0", '"m\\u0061s" = 2.0')
    message = error_of(text)
    line = next(i for i, row in enumerate(text.splitlines(), 1) if row.startswith('"m'))
    assert line > 1
    assert located(message, "case.toml", line, "material.mas")


# -- error messages name the file, the key path and its line ------------------------------
def located(message: str, source: str, line: int, path: str) -> bool:
    return f"{source}:{line}: {path}:" in message


def test_unknown_key_is_named_with_file_line_and_allowed_keys():
    text = PLANE.replace("mass = 2.0", "mas = 2.0")
    message = error_of(text)
    line = text.splitlines().index("mas = 2.0") + 1
    assert located(message, "case.toml", line, "material.mas")
    assert "unknown key" in message and "mass_matrix" in message


def test_unknown_table_is_reported():
    text = STATIC + "[solver]\nkind = 'static'\n"
    line = text.splitlines().index("[solver]") + 1
    message = error_of(text)
    assert f"case.toml:{line}: solver:" in message and "[solve]" in message


def test_wrong_type_in_an_array_of_tables():
    text = PLANE.replace("force = [0.0, 0.0, -0.1]", 'force = "down"')
    message = error_of(text)
    line = text.splitlines().index('force = "down"') + 1
    assert located(message, "case.toml", line, "load[2].force")
    assert "an array of 3 numbers [fx, fy, fz]" in message and "'down'" in message


def test_missing_field_points_at_its_table():
    text = PLANE.replace("q = 0.2\n", "")
    message = error_of(text)
    header = [i for i, line in enumerate(text.splitlines(), 1) if line == "[[load]]"][2]
    assert located(message, "case.toml", header, "load[3].q")
    assert "missing" in message and "a number" in message


def test_missing_required_table_and_key():
    message = error_of('[surface]\ncells = 4\n[material]\nw10 = 1.0\n')
    assert "case.toml:1: surface.shape: missing" in message
    assert "case.toml: solve: missing table [solve]" in message
    assert '"plane"' in message   # says what is allowed


def test_value_out_of_range_names_the_bound():
    text = PLANE.replace("damping = 0.5", "damping = -1")
    message = error_of(text)
    line = text.splitlines().index("damping = -1") + 1
    assert located(message, "case.toml", line, "material.damping")
    assert "a number >= 0" in message and "-1" in message


def test_element_of_a_multiline_array_is_located_on_its_own_line():
    text = PLANE.replace("          [0.3, 0.5]]", "          [-0.3, 0.5]]")
    message = error_of(text)
    line = text.splitlines().index("          [-0.3, 0.5]]   # a multi-line array") + 1
    assert located(message, "case.toml", line, "load[2].points[2]")
    assert "increasing" in message


def test_bad_element_in_a_list_is_located_by_index():
    text = PLANE.replace('formats = ["obj", "report"]', 'formats = ["obj", "jpeg"]')
    message = error_of(text)
    line = text.splitlines().index('formats = ["obj", "jpeg"]') + 1
    assert located(message, "case.toml", line, "output.formats[2]")
    assert '"gif"' in message


def test_keys_that_do_not_apply_are_refused():
    message = error_of(PLANE.replace("q = 0.2", "q = 0.2\nat = [0.1, 0.1]"))
    assert "load[3].at: does not apply to a pressure load" in message
    message = error_of(STATIC.replace('kind = "static"', 'kind = "static"\nt_end = 1.0'))
    assert "solve.t_end: does not apply to kind 'static'" in message
    message = error_of(PLANE.replace("size = [2.0, 1.0]", "radius = 1.0"))
    assert "surface.radius: is not a parameter of shape 'plane'" in message


def test_several_problems_are_reported_together_in_line_order():
    text = PLANE.replace("degree = 2", "degree = 0").replace("frames = 5", "frames = 1.5")
    message = error_of(text)
    assert message.startswith("case.toml: 2 problems")
    first, second = message.splitlines()[1:3]
    assert "surface.degree" in first and "an integer >= 1 and <= 7" in first
    assert "solve.frames" in second and "got float 1.5" in second


def test_cross_field_rules():
    assert "t_off: must be > t_on" in error_of(PLANE.replace("t_off = 0.5", "t_off = 0.05"))
    assert "give either frames or times" in error_of(
        NEWMARK.replace('times = [0.0, 0.25, 1.0]', 'times = [0.0, 1.0]\nframes = 3'))
    assert "needs an end time" in error_of(PLANE.replace("t_end = 1.0\n", ""))
    assert "all stiffness weights are zero" in error_of(
        STATIC.replace("w10 = 1.0\nw01 = 1.0", "mass = 1.0"))
    assert "degree must be >= 2" in error_of(NEWMARK.replace("cells = 3", "cells = 3\ndegree = 1"))
    assert "needs at least one [[load]]" in error_of(MODES.replace('"modes"\nmodes = 4\nframes = 6',
                                                                   '"static"'))
    assert "times must be <= t_end" in error_of(
        NEWMARK.replace("times = [0.0, 0.25, 1.0]", "times = [0.0, 2.0]\nt_end = 1.0"))


def test_toml_syntax_error_names_file_and_line():
    message = error_of("[surface]\nshape = plane\n", source="bad.toml")
    assert message.startswith("bad.toml:2: TOML syntax error")


def test_files_are_named_in_messages(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text(STATIC.replace("cells = 3", "cells = 0"))
    with pytest.raises(ScenarioError, match=r"broken\.toml:4: surface\.cells: expected"):
        load_scenario(path)
    with pytest.raises(ScenarioError, match="not found"):
        load_scenario(tmp_path / "absent.toml")
    assert issubclass(ScenarioError, InputError)


def test_overrides_are_validated_and_named_by_origin():
    s = parse_scenario(PLANE, source="case.toml")
    newmark = with_overrides(s, {"solve.method": "newmark", "solve.rtol": None,
                                 "solve.atol": None}, origin="--method")
    assert newmark.solve.method == "newmark"
    with pytest.raises(ScenarioError, match=r"case\.toml \(--frames\): solve\.frames"):
        with_overrides(s, {"solve.frames": 1}, origin="--frames")
    coarse = with_overrides(s, {"load.profile": "constant", "load.t_on": None,
                                "load.t_off": None, "load.points": None, "load.omega": None,
                                "load.phase": None})
    assert {ld.profile for ld in coarse.loads} == {"constant"}


# -- building ---------------------------------------------------------------------------------
@pytest.fixture
def shapes():
    return pytest.importorskip("splinedeform.shapes")


def test_free_region_fixes_control_points_outside_the_box(shapes):
    s = parse_scenario(PLANE)
    built = build(s)
    gu, gv = built.surface.basis_u.greville(), built.surface.basis_v.greville()
    expected = ~(((gu >= 0.2) & (gu <= 1.8))[:, None] & ((gv >= 0.0) & (gv <= 0.9))[None, :])
    # the mask as 0/1: integers, compared to half a unit (no Greville abscissa lies
    # within round-off of the box's sides 0.2, 1.8, 0.9; its side v = 0 is the first
    # abscissa, exactly 0 as the average of zero knots)
    mask = free_region_mask(s, built.surface)
    assert mask.shape == expected.shape
    assert np.abs(mask.astype(float) - expected.astype(float)).max() <= 0.5
    assert expected.any() and not expected.all()


def test_loads_become_library_loads_with_their_profiles(shapes):
    from splinedeform import loads as L

    s = parse_scenario(PLANE)
    surface = build(s).surface
    load = build_load(s)
    reference = (L.Point(1.0, 0.5, [0, 0, -1.0], L.Step(0.1, 0.5))
                 + L.Uniform([0, 0, -0.1], L.Piecewise([(0.0, 1.0), (0.3, 0.5)]))
                 + L.Pressure(0.2, L.Harmonic(3.0, 0.5)))
    for t in (0.0, 0.2, 0.4, 0.7):
        np.testing.assert_allclose(load.vector(surface, t), reference.vector(surface, t),
                                   rtol=1e-14, atol=1e-14)


def test_built_model_uses_material_boundary_and_mass_matrix(shapes):
    s = parse_scenario(MODES)
    model = build(s).model
    assert model.material.w10 == 1.0 and model.mass_matrix == "consistent"
    n_u, n_v = model.surface.shape
    assert model.n_free == (n_u - 2) * (n_v - 2)   # open knots, pinned edges: one row each


@pytest.mark.parametrize("shape", sorted(SHAPE_TEXTS))
def test_every_built_in_shape_builds_with_its_documented_parameters(shape, shapes):
    built = build(parse_scenario(SHAPE_TEXTS[shape]))
    assert np.all(np.isfinite(built.surface.control_points))


def test_shape_parameters_match_the_shape_functions(shapes):
    import inspect

    for shape, params in SHAPE_PARAMETERS.items():
        if shape in ("file", "cad"):
            continue
        signature = inspect.signature(getattr(shapes, shape)).parameters
        # knots_v of the cylinder is covered by knots (a single layout sets v for a cylinder)
        fitting = ("cells", "degree", "knots", "method", "name", "knots_v")
        own = {k for k in signature if k not in fitting}
        assert own == set(params), shape


def test_domain_is_checked_after_building(tmp_path, shapes):
    text = STATIC + "[output]\nprobes = [[0.5, 1.5]]\n"
    with pytest.raises(ScenarioError, match=r"output\.probes\[1\]: v = 1\.5 is outside"):
        build(parse_scenario(text, source="case.toml"))
    text = STATIC + "[output]\nprobes = [[0.5, 0.5]]\n"
    text = text.replace("[boundary]", '[boundary]\nfree_region = { u = [0.41, 0.42] }')
    with pytest.raises(ScenarioError, match="no control point"):
        build(parse_scenario(text))


def test_library_errors_are_located_at_the_scenario_key(shapes):
    text = STATIC.replace('u0 = "pinned"\nu1 = "pinned"\nv0 = "pinned"\nv1 = "pinned"', "")
    s = parse_scenario(text, source="case.toml")
    from splinedeform.pipeline import run
    line = text.splitlines().index("[solve]") + 1
    with pytest.raises(ScenarioError, match=rf"case\.toml:{line}: solve: .*unconstrained"):
        run(with_overrides(s, {"output.formats": []}))


def test_surface_from_control_net_and_point_grid_files(tmp_path, shapes):
    from splinedeform.export import write_control_nets

    basis = BSplineBasis(2, 3, 1.0, "open")
    g = basis.greville()
    P = np.stack(np.broadcast_arrays(g[:, None], g[None, :], 0.1 * g[:, None] ** 2), -1)
    surface = Surface(P, basis, basis)
    write_control_nets(tmp_path, "net", surface, [0.0, 1.0], np.stack([P, 2 * P]))
    s = parse_scenario(FILE_TEXTS[0], directory=tmp_path)
    # frame 0 read back from the written net: a float64 round trip, one rounding allowed
    np.testing.assert_allclose(build(s).surface.control_points, P, rtol=0,
                               atol=4 * np.finfo(float).eps * np.abs(P).max())
    u = np.linspace(0.0, 1.0, 7)
    grid = np.stack(np.broadcast_arrays(u[:, None], u[None, :], (u[:, None] * u[None, :])), -1)
    np.save(tmp_path / "grid.npy", grid)
    fitted = build(parse_scenario(FILE_TEXTS[1], directory=tmp_path)).surface
    assert fitted.shape == (5, 5)                                       # 3 cells, degree 2
    # x = u, y = v, z = u v lies in the space: the fit reproduces it at the grid points,
    # spread evenly over the default domain (the grid's mean chord lengths)
    (_, lu), (_, lv) = fitted.domain
    np.testing.assert_allclose(fitted.evaluate_grid(np.linspace(0, lu, 7),
                                                    np.linspace(0, lv, 7)), grid, atol=1e-10)


def test_control_net_files_refuse_fitting_keys(tmp_path, shapes):
    from splinedeform.export import write_control_nets

    basis = BSplineBasis(2, 3, 1.0, "open")
    P = np.zeros((5, 5, 3))
    P[..., 0] = basis.greville()[:, None]
    write_control_nets(tmp_path, "net", Surface(P, basis, basis), [0.0], P[None])
    text = file_scenario("net.json", "cells = 3")
    with pytest.raises(ScenarioError, match=r"case\.toml:4: surface\.cells: does not apply"):
        build(parse_scenario(text, source="case.toml", directory=tmp_path))


def test_describe_says_what_would_run(shapes):
    s = parse_scenario(PLANE)
    rows = dict(describe(s, build(s)))
    assert rows["solve"] == "dynamic with rk45 to t = 1"
    assert rows["loads"] == "point (step), uniform (piecewise), pressure (harmonic)"
    assert isinstance(s, Scenario)


def test_doc_lists_every_output_format():
    from splinedeform.scenario import FORMAT_ALIASES, FORMATS

    text = DOC.read_text(encoding="utf-8")
    table = text[text.index("| name | writes |"):]
    named = set(re.findall(r"\*\*([a-z0-9]+)\*\*", table))
    assert named == set(FORMATS) | set(FORMAT_ALIASES)


# -- robustness: any wrong value gives a ScenarioError, never another exception ------------
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

TOML_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-10**6, 10**6)
    | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
        st.sampled_from(["u", "v", "kind", "x"]), inner, max_size=3),
    max_leaves=8)


def document(raw: dict) -> str:
    """TOML text of a document given as nested dicts (tables as inline tables)."""
    from splinedeform.scenario import _toml_value

    def clean(value):   # TOML has no null: drop None
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items() if v is not None}
        if isinstance(value, list):
            return [clean(v) for v in value if v is not None]
        return value
    return "\n".join(f"{k} = {_toml_value(v)}" for k, v in clean(raw).items()
                     if v is not None) + "\n"


@settings(max_examples=150, deadline=None)
@given(table=st.sampled_from(sorted(COVERAGE)), data=st.data(), value=TOML_VALUES)
def test_any_wrong_value_is_a_scenario_error(table, data, value):
    import tomllib

    raw = tomllib.loads(COVERAGE[table])
    section = data.draw(st.sampled_from(sorted(raw)))
    target = raw[section]
    if isinstance(target, list):
        target = target[0]
    if isinstance(target, dict):
        key = data.draw(st.sampled_from(sorted(target) + ["extra"]))
        target[key] = value
    else:
        raw[section] = value
    try:
        parse_scenario(document(raw))
    except ScenarioError as exc:
        assert "<scenario>" in str(exc) and "TOML syntax error" not in str(exc)


def test_printed_strings_survive_control_characters():
    s = parse_scenario('title = "a\\u007fb\\u0001\\\\ \\" é"\n' + STATIC)
    assert parse_scenario(scenario_to_toml(s)).title == s.title == 'a\x7fb\x01\\ " é'
