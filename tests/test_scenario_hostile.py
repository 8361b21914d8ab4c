"""Hostile and extreme scenario files: every one is a located ScenarioError, never a traceback.

Scenario files are shared between people, so besides absurd values these tests cover files
that try to read outside their own folder (``surface.path``).
"""

import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import BSplineBasis, ScenarioError, Surface
from splinedeform.scenario import _located, load_scenario, parse_scenario, scenario_to_toml

from tiny_scenario import DYNAMIC


def line_of(text: str, start: str) -> int:
    """Line (from 1) of the first line of ``text`` starting with ``start``."""
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def error_of(text: str) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="case.toml")
    return str(info.value)


# -- values ---------------------------------------------------------------------------------
@pytest.mark.parametrize("depth", [65, 5000])
def test_deep_nesting_is_a_located_error_not_a_recursion_error(depth):
    for opening, closing in (("[", "]"), ("{a = ", "}")):
        text = f"title = \"x\"\nnested = {opening * depth}1{closing * depth}\n" + DYNAMIC
        assert error_of(text).startswith("case.toml:2: arrays or inline tables nested more than")


def test_brackets_inside_strings_and_comments_are_not_nesting():
    text = f'title = "{"[" * 200}"  # {"{" * 200}\n' + DYNAMIC
    assert parse_scenario(text).title == "[" * 200


@pytest.mark.parametrize("key, value", [("t_end", "1e308"), ("t_end", "inf"),
                                        ("times", "[0.0, 1e300]")])
def test_times_beyond_any_meaningful_phase_name_their_key(key, value):
    text = DYNAMIC.replace("t_end = 2.0\nframes = 5", f"{key} = {value}")
    message = error_of(text)
    assert f"case.toml:{line_of(text, key)}: solve.{key}" in message and "<= 1e+12" in message


@pytest.mark.parametrize("value", ["0", "-3", "2.5"])
def test_function_samples_must_be_a_positive_integer(value):
    text = DYNAMIC + f"function_samples = {value}\n"
    message = error_of(text)
    assert f"case.toml:{line_of(text, 'function_samples')}: solve.function_samples: expected an integer >= 1" in message


def test_function_samples_applies_to_the_analytic_method_only():
    s = parse_scenario(DYNAMIC + "function_samples = 64\n")
    assert s.solve.function_samples == 64
    assert parse_scenario(scenario_to_toml(s)).solve.function_samples == 64
    message = error_of(DYNAMIC + 'method = "rk45"\nfunction_samples = 64\n')
    assert "solve.function_samples: does not apply to method 'rk45'" in message


def test_numerical_failures_while_building_are_located():
    s = parse_scenario(DYNAMIC, source="case.toml")
    for exc in (ValueError("bad"), np.linalg.LinAlgError("not positive definite"),
                OverflowError("math range error")):
        with pytest.raises(ScenarioError) as info, _located(s, "material"):
            raise exc
        message = str(info.value)
        assert message.startswith(f"case.toml:{line_of(DYNAMIC, '[material]')}: material: numerical failure")
        assert type(exc).__name__ in message and str(exc) in message


def test_a_denormal_mass_is_a_located_error():
    from splinedeform.pipeline import run

    text = DYNAMIC.replace("[material]\n", "[material]\nmass = 1e-320\n")
    with pytest.raises(ScenarioError, match=r"^case\.toml:\d+: "):   # refused on reading or later
        run(parse_scenario(text + "[output]\nformats = []\n", source="case.toml"))


# -- files outside the scenario's folder ----------------------------------------------------
def file_text(path: str) -> str:
    return (f'[surface]\nshape = "file"\npath = "{path}"\n'
            '[material]\nw10 = 1.0\nw01 = 1.0\n[solve]\nkind = "modes"\nmodes = 2\n')


@pytest.fixture
def layout(tmp_path: Path) -> Path:
    """``tmp/secret/net.json`` outside, ``tmp/shared/`` the scenario folder, ``inner/net.json``."""
    from splinedeform.export import write_control_nets

    basis = BSplineBasis(2, 3, 1.0, "open")
    P = np.zeros((5, 5, 3))
    P[..., 0] = basis.greville()[:, None]
    P[..., 1] = basis.greville()[None, :]
    for folder in (tmp_path / "secret", tmp_path / "shared" / "inner"):
        folder.mkdir(parents=True)
        write_control_nets(folder, "net", Surface(P, basis, basis), [0.0], P[None])
    return tmp_path


def write_scenario(layout: Path, path: str) -> Path:
    scenario = layout / "shared" / "case.toml"
    scenario.write_text(file_text(path))
    return scenario


def test_paths_inside_the_folder_are_read(layout):
    for path in ("inner/net.json", "inner/../inner/net.json",
                 str(layout / "shared" / "inner" / "net.json")):
        s = load_scenario(write_scenario(layout, path))
        assert s.surface.path == (layout / "shared" / "inner" / "net.json").resolve()


@pytest.mark.parametrize("kind", ["dotdot", "absolute", "symlink"])
def test_paths_leaving_the_folder_are_refused_without_saying_if_they_exist(layout, kind):
    outside = layout / "secret" / "net.json"
    if kind == "symlink":
        (layout / "shared" / "link.json").symlink_to(outside)
        (layout / "shared" / "dangling.json").symlink_to(layout / "secret" / "absent.json")
        existing, absent = "link.json", "dangling.json"
    elif kind == "dotdot":
        existing, absent = "../secret/net.json", "../secret/absent.json"
    else:
        existing, absent = str(outside), str(layout / "secret" / "absent.json")
    messages = []
    for path in (existing, absent):
        with pytest.raises(ScenarioError) as info:
            load_scenario(write_scenario(layout, path))
        messages.append(str(info.value).replace(path, "<path>"))
    assert "case.toml:3: surface.path: '<path>' lies outside the scenario's folder" in messages[0]
    assert "--allow-outside-paths" in messages[0] and "allow_outside_paths=True" in messages[0]
    assert messages[0] == messages[1]          # nothing tells whether the file exists
    assert "secret" not in messages[0].replace(str(layout / "secret"), "")
    s = load_scenario(write_scenario(layout, existing), allow_outside_paths=True)
    assert s.surface.path == outside.resolve()


def test_the_opt_in_survives_overrides_and_reaches_the_command_line(layout):
    from splinedeform import cli
    from splinedeform.scenario import with_overrides

    scenario = write_scenario(layout, "../secret/net.json")
    s = load_scenario(scenario, allow_outside_paths=True)
    assert with_overrides(s, {"solve.modes": 3}).solve.modes == 3
    runner = CliRunner()
    refused = runner.invoke(cli.app, ["validate", str(scenario)])
    assert refused.exit_code != 0 and "outside the scenario's folder" in refused.output
    allowed = runner.invoke(cli.app, ["validate", "--allow-outside-paths", str(scenario)])
    assert allowed.exit_code == 0, allowed.output


# -- files that are not what they seem ------------------------------------------------------
def unblock_after(path: Path, seconds: float = 10.0) -> None:
    """Should a reader block on the named pipe ``path`` (the bug), open it for writing after
    ``seconds`` so that the reader sees an empty file and the test fails instead of hanging."""
    import os
    import threading
    import time

    def writer() -> None:
        time.sleep(seconds)
        try:
            os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:
            pass              # no reader waiting: nothing to unblock
    threading.Thread(target=writer, daemon=True).start()


@pytest.mark.parametrize("name", ["case.toml", "net.json", "net.npz", "grid.npy"])
def test_a_named_pipe_is_refused_without_waiting_for_a_writer(tmp_path, name):
    import os

    from splinedeform.scenario import build

    if not hasattr(os, "mkfifo"):
        pytest.skip("no named pipes on this system")
    pipe = tmp_path / name
    os.mkfifo(pipe)
    unblock_after(pipe)
    with pytest.raises(ScenarioError) as info:
        if name == "case.toml":
            load_scenario(pipe)
        else:
            scenario = tmp_path / "uses.toml"
            scenario.write_text(file_text(name))
            build(load_scenario(scenario))
    message = str(info.value)
    assert f"{pipe}: the " in message and "is a named pipe, not a regular file" in message
    if name != "case.toml":
        assert message.startswith("uses.toml:3: surface.path: ") or ":3: surface.path: " in message


def test_an_array_header_declaring_more_than_memory_is_refused_before_reading(tmp_path):
    # a 128-byte .npy header that claims a (1e6, 1e6, 3) float64 grid (24 TB) and holds
    # nothing: refused from the header, before numpy allocates
    import numpy.lib.format as fmt

    from splinedeform.scenario import build

    grid = tmp_path / "grid.npy"
    with open(grid, "wb") as fh:
        fmt.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False,
                                        "shape": (10**6, 10**6, 3)})
    scenario = tmp_path / "case.toml"
    scenario.write_text(file_text("grid.npy"))
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(scenario))
    assert "case.toml:3: surface.path: " in str(info.value)
    assert "its arrays would take 2.24e+04 GiB, more than the 4 GiB" in str(info.value)


def test_npz_members_are_counted_by_their_declared_sizes(tmp_path):
    # a compressed .npz of 2 MB of zeros (a few KB on disk) against a 1 MB cap: refused from
    # the zip directory and the member's header; under a 4 MB cap it is read
    from splinedeform import InputError
    from splinedeform.input_files import check_array_file

    path = tmp_path / "zeros.npz"
    np.savez_compressed(path, points=np.zeros((500, 500)))
    assert path.stat().st_size < 50_000
    with open(path, "rb") as fh:
        with pytest.raises(InputError, match=r"zeros\.npz: its arrays would take"):
            check_array_file(fh, path, max_bytes=1e6)
        check_array_file(fh, path, max_bytes=4e6)
        assert fh.tell() == 0


def test_deeply_nested_json_in_a_net_file_is_an_error_naming_the_file(tmp_path):
    from splinedeform import InputError
    from splinedeform.export import read_control_net
    from splinedeform.scenario import build

    net = tmp_path / "net.json"
    net.write_text('{"control_points": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(InputError, match=rf"^{re.escape(str(net))}: arrays or objects nested "
                                         "too deep"):
        read_control_net(net)
    scenario = tmp_path / "case.toml"
    scenario.write_text(file_text("net.json"))
    with pytest.raises(ScenarioError, match="case.toml:3: surface.path: .*nested too deep"):
        build(load_scenario(scenario))


def test_a_byte_order_mark_at_the_start_of_a_scenario_is_accepted(tmp_path):
    path = tmp_path / "case.toml"
    path.write_bytes(b"\xef\xbb\xbf" + DYNAMIC.encode("utf-8"))
    s = load_scenario(path)
    assert s.solve.frames == 5 and s.lines == parse_scenario(DYNAMIC).lines
    assert parse_scenario("\ufeff" + DYNAMIC).solve.t_end == 2.0
    message = error_of("\ufeff" + DYNAMIC.replace("frames = 5", "frames = 0"))
    assert message.startswith(f"case.toml:{line_of(DYNAMIC, 'frames')}: solve.frames: ")


# -- extreme lengths --------------------------------------------------------------------
@pytest.mark.parametrize("surface, key, words", [
    ('shape = "saddle"\ncells = 3\nheight = 1e200', "height", "a length of 1e+200 is outside"),
    ('shape = "plane"\ncells = 3\nsize = 1e300', "size", "a length of 1e+300 is outside"),
    ('shape = "cylinder"\ncells = 4\nradius = 1e-300', "radius", "a length of 1e-300 is outside"),
    ('shape = "saddle"\ncells = 3\nheight = 1e15', "height",
     "surface.height = 1e+15 against surface.size = 1: a ratio beyond 1e+12"),
    ('shape = "torus"\ncells = 4\nR = 1.0\nr = 1e-13', "r",
     "surface.r = 1e-13 against surface.R = 1: a ratio beyond 1e+12"),
])
def test_an_extreme_length_is_named_by_its_key(surface, key, words):
    # these used to surface as a boundary, periodic-basis or "no single input is extreme"
    # error far from the cause
    text = DYNAMIC.replace('shape = "plane"\ncells = 3', surface)
    message = error_of(text)
    assert message.startswith(f"case.toml:{line_of(text, key + ' =')}: surface.{key}: {words}")


@pytest.mark.parametrize("thickness, words", [
    ("1e-100", "a thickness of 1e-100 is outside 1e-50 .. 1e+50"),
    ("1e-8", "1e-08 is below 1e-06 times the shape's size 1"),
])
def test_an_extreme_shell_thickness_is_named(thickness, words):
    text = DYNAMIC.replace("w10 = 1.0\nw01 = 1.0", 'physics = "shell"\nE = 1.0\nnu = 0.3\n'
                                                   f"thickness = {thickness}\ndensity = 1.0")
    message = error_of(text)
    assert message.startswith(f"case.toml:{line_of(text, 'thickness')}: material.thickness: "
                              f"{words}")


def test_ordinary_lengths_in_other_units_are_accepted():
    # nanometres and kilometres are far from 1 but well inside the usable range
    for surface in ('shape = "plane"\ncells = 3\nsize = 1e-9', 'shape = "saddle"\ncells = 3\n'
                    'size = 1e3\nheight = 250.0', 'shape = "saddle"\ncells = 3\nheight = 0.0'):
        parse_scenario(DYNAMIC.replace('shape = "plane"\ncells = 3', surface))


def test_a_net_file_of_extreme_extent_is_named_by_its_path(tmp_path):
    from splinedeform.export import write_control_nets
    from splinedeform.scenario import build

    basis = BSplineBasis(2, 3, 1.0, "open")
    P = np.zeros((5, 5, 3))
    P[..., 0] = 1e200 * basis.greville()[:, None]
    P[..., 1] = 1e200 * basis.greville()[None, :]
    write_control_nets(tmp_path, "net", Surface(P, basis, basis), [0.0], P[None])
    scenario = tmp_path / "case.toml"
    scenario.write_text(file_text("net.json"))
    with pytest.raises(ScenarioError, match=r"case\.toml:3: surface\.path: the surface spans "
                                            r"1e\+200, outside 1e-50 \.\. 1e\+50"):
        build(load_scenario(scenario))
