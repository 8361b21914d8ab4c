"""The per-mode files of a modes solve: mode fields for ParaView, nets and animations.

Independent references: the Rayleigh quotient ``dᵀ K d / dᵀ M d`` of a written mode,
which is ``ω_k²`` only if the file holds the k-th eigenvector; the surface evaluated
point by point (:meth:`Surface.evaluate`) against the ``.vtu`` fields; the names and
counts promised in docs/outputs.md.
"""

from __future__ import annotations

import numpy as np
import pytest

from splinedeform import InputError, viz
from splinedeform.export import read_control_net, read_manifest, write_mode_fields
from splinedeform.pipeline import run
from splinedeform.scenario import parse_scenario

meshio = pytest.importorskip("meshio")

DRUM = """\
[surface]
shape = "plane"
cells = 4

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
modes = 3
frames = 5

[output]
formats = {formats}
resolution = 6
animate_modes = [1, 3]
"""


def drum(formats: str):
    return parse_scenario(DRUM.format(formats=formats), source="drum.toml")


@pytest.fixture(scope="module")
def drum_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drum")
    return run(drum('["vtu", "json", "npz", "gif"]'), folder), folder


def test_a_modes_solve_writes_every_mode(drum_run):
    result, folder = drum_run
    names = {p.name for p in folder.iterdir()}
    per_mode = {"drum_modes.vtu", "drum_mode3.gif",
                *(f"drum_mode{k}_nets.{ext}" for k in (1, 2, 3) for ext in ("json", "npz"))}
    assert per_mode <= names
    assert "drum_mode1.gif" not in names and "drum.gif" in names    # mode 1 is drum.gif
    listed = {entry["name"] for entry in read_manifest(folder / "drum.manifest.json")["files"]}
    assert per_mode <= listed


def test_each_mode_net_is_its_eigenvector(drum_run):
    """Frame 1 (phase 1/4: sin = 1) of mode k's nets is D_k; its Rayleigh quotient with the
    model's K and M is ω_k² (1e-9: rounding of the eigen-solution and the float64 file)."""
    result, folder = drum_run
    model, rest = result.built.model, result.rest_net
    for k in (1, 2, 3):
        net = read_control_net(folder / f"drum_mode{k}_nets.json", frame=1).control_points
        d = (net - rest)[..., 2].ravel()          # a plane's modes move along z only
        np.testing.assert_allclose((net - rest)[..., :2], 0.0, atol=1e-14)
        quotient = d @ (model.K_full @ d) / (d @ (model.M_full @ d))
        assert quotient == pytest.approx(float(result.omegas[k - 1]) ** 2, rel=1e-9)
        # scaled as drawn: the largest control-point displacement is 0.1 x the net's size
        assert np.abs(d).max() == pytest.approx(0.1 * 1.0, rel=1e-12)
        back = read_control_net(folder / f"drum_mode{k}_nets.npz", frame=4).control_points
        np.testing.assert_allclose(back, rest, atol=1e-15)        # sin(2π) ~ 2.4e-16


def test_the_mode_fields_are_the_modes_on_the_rest_mesh(drum_run):
    result, folder = drum_run
    mesh = meshio.read(folder / "drum_modes.vtu")
    s = result.built.surface
    u, v = s.sample_parameters(6)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    np.testing.assert_allclose(mesh.points, s.evaluate(uu, vv).reshape(-1, 3), atol=1e-12)
    for k in (1, 2, 3):
        moved = s.with_control_points(result.rest_net + result.mode_nets[k - 1])
        expected = (moved.evaluate(uu, vv) - s.evaluate(uu, vv)).reshape(-1, 3)
        # 1e-12: sums of a few products of numbers of order 1
        np.testing.assert_allclose(mesh.point_data[f"mode_{k}"], expected, atol=1e-12)
    assert "mode_4" not in mesh.point_data


def test_the_mode_animation_shows_that_mode(drum_run):
    """Mode 3 (ω₃ = ω₂ of the square drum: a nodal line) differs from mode 1's film."""
    _, folder = drum_run
    iio = pytest.importorskip("imageio.v3")
    one, three = iio.imread(folder / "drum.gif", index=1), iio.imread(folder / "drum_mode3.gif",
                                                                      index=1)
    assert np.mean(np.any(one != three, axis=-1)) > 0.01


def test_animate_modes_is_checked_against_the_modes_computed():
    with pytest.raises(Exception, match=r"output.animate_modes\[2\].*mode 5 is not computed"):
        parse_scenario(DRUM.format(formats="[]").replace("[1, 3]", "[1, 5]"), source="d.toml")


def test_write_mode_fields_refuses_a_wrong_shape(tmp_path):
    from splinedeform import shapes

    plane = shapes.plane(cells=2)
    with pytest.raises(InputError, match="mode nets"):
        write_mode_fields(tmp_path / "m.vtu", plane, np.zeros((2, 3, 3, 3)))
    assert list(tmp_path.iterdir()) == []
