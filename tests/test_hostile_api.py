"""Hostile and extreme input to the library API: a clear InputError, never a silent answer."""
from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.errors import InputError
from splinedeform.loads import Harmonic, Step, Uniform


def _clamped_model() -> sd.Model:
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=(4, 4), degree=3)
    return sd.Model(surf, sd.Material(mass=1.0, w10=1.0, w01=1.0), boundary="clamped")


@pytest.mark.parametrize("profile", [Step(t_on=1.0), Harmonic(omega=2.0), Step(t_on=0.0, t_off=2.0)])
def test_static_refuses_a_time_dependent_load_without_a_time(profile):
    model = _clamped_model()
    with pytest.raises(InputError, match=r"static\(load, t=\.\.\.\)"):
        model.static(Uniform((0, 0, -1.0), profile=profile))


def test_static_at_an_explicit_time_equals_the_constant_load_scaled_by_the_profile():
    # A step on at t_on = 1: before it the equilibrium is zero, after it equals the constant
    # load's; the two solves share one factorisation path, so agreement to 1e-12 relative
    # (round-off of a well-conditioned 4x4-cell clamped membrane) is expected.
    model = _clamped_model()
    constant = model.static(Uniform((0, 0, -1.0))).control_points() - model.surface.control_points
    step = Uniform((0, 0, -1.0), profile=Step(t_on=1.0))
    before = model.static(step, t=0.5).control_points() - model.surface.control_points
    after = model.static(step, t=1.5).control_points() - model.surface.control_points
    scale = np.abs(constant).max()
    assert scale > 0
    assert np.abs(before).max() <= 1e-14 * scale
    assert np.allclose(after, constant, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("t", [-1.0, float("nan"), float("inf")])
def test_static_refuses_a_bad_time(t):
    with pytest.raises(InputError, match="static time t"):
        _clamped_model().static(Uniform((0, 0, -1.0)), t=t)


@pytest.mark.parametrize("value", [True, False, np.True_, 1 + 2j, "1", -1.0, float("nan"), float("inf")])
def test_material_refuses_non_real_values_naming_the_parameter(value):
    with pytest.raises(InputError, match="material.w10"):
        sd.Material(mass=1.0, w10=value, w01=1.0)


HOSTILE = ('__SPLINEDEFORM_DATA__ </script><img src=x onerror="document.title=1"> '
           '/*__SPLINEDEFORM_THREE__*/ & \u2028 __SPLINEDEFORM_TITLE__')


def test_viewer_page_keeps_a_hostile_name_inert_and_round_trips_it():
    import json
    import re

    from splinedeform.viz import viewer_html
    data = {"name": HOSTILE, "frames": []}
    page = viewer_html(data)
    assert "<img" not in page                       # neither the title nor the data opens a tag
    block = re.search(r'<script type="application/json" id="splinedeform-data">(.*?)</script>',
                      page, re.S)
    assert block is not None
    assert json.loads(block.group(1)) == data       # the JSON decodes to exactly the data given
    assert page.count('id="splinedeform-data"') == 1


def test_report_markdown_escapes_a_hostile_title():
    from splinedeform.export import report_markdown
    text = report_markdown({}, title='<img src=x onerror="alert(1)">\n# injected')
    first = text.splitlines()[0]
    assert "<img" not in text and first.startswith("# &lt;img")
    assert "\n# injected" not in text                 # a newline cannot start a new heading


# -- periodic directions, coincident and complex point grids ---------------------------------
@pytest.mark.parametrize("call, direction, gap", [
    (lambda: sd.shapes.plane(size=(2.0, 1.0), knots="periodic"), "u", 2.0),
    (lambda: sd.shapes.plane(size=(2.0, 1.0), knots=("open", "periodic")), "v", 1.0),
    (lambda: sd.shapes.tile(angle=1.0, knots=("periodic", "open")), "u", 2 * np.sin(0.5)),
    (lambda: sd.shapes.half_sphere(knots=("periodic", "periodic")), "v", np.sqrt(2.0)),
    (lambda: sd.shapes.cylinder(height=3.0, knots="periodic"), "v", 3.0),
])
def test_a_periodic_direction_on_an_open_shape_is_refused_naming_direction_and_gap(call, direction, gap):
    # The gap is a closed form of the shape (plane side, tile chord 2R sin(angle/2), the
    # rim-to-pole chord R√2 of the half sphere, cylinder height), printed to 3 digits.
    with pytest.raises(InputError) as info:
        call()
    message = str(info.value)
    assert f"not closed in {direction}" in message
    assert f"{gap:.3g} apart" in message


@pytest.mark.parametrize("call", [
    lambda: sd.shapes.cylinder(cells=(8, 4)),
    lambda: sd.shapes.torus(cells=(8, 6)),
    lambda: sd.shapes.half_sphere(cells=(8, 4)),
])
def test_closed_shapes_keep_their_periodic_knots(call):
    assert call().basis_u.periodic


def test_a_periodic_point_grid_must_go_round():
    u = np.linspace(0.0, 1.0, 12)
    grid = np.stack(np.broadcast_arrays(u[:, None], u[None, :], 0.0 * u[:, None]), -1)
    with pytest.raises(InputError, match=r"point grid is not closed in u: .* 1 apart"):
        sd.shapes.from_points(grid, cells=(5, 4), knots=("periodic", "open"))


@pytest.mark.parametrize("grid, words", [
    (np.zeros((6, 6, 3)), "all 36 points coincide"),
    (np.ones((5, 7, 3)) * [1.0, 2.0, 3.0], "all 35 points coincide"),
])
def test_coincident_points_are_refused(grid, words):
    with pytest.raises(InputError, match=words):
        sd.shapes.from_points(grid, cells=2, degree=2)


def test_a_repeated_row_of_a_point_grid_is_refused_naming_it():
    u = np.array([0.0, 0.25, 0.5, 0.5, 1.0])
    v = np.linspace(0.0, 1.0, 5)
    grid = np.stack(np.broadcast_arrays(u[:, None], v[None, :], 0.0 * u[:, None]), -1)
    with pytest.raises(InputError, match=r"rows 2 and 3 \(u direction\) coincide"):
        sd.shapes.from_points(grid, cells=2, degree=2)
    with pytest.raises(InputError, match=r"columns 2 and 3 \(v direction\) coincide"):
        sd.shapes.from_points(grid.transpose(1, 0, 2)[..., [1, 0, 2]], cells=2, degree=2)


def test_a_pole_row_is_not_a_coincidence():
    # a half sphere sampled on a grid: its last column is the pole, all points equal
    t, p = np.linspace(0, 2 * np.pi, 17), np.linspace(0, np.pi / 2, 6)
    grid = np.stack([np.cos(p)[None, :] * np.cos(t)[:, None], np.cos(p)[None, :] * np.sin(t)[:, None],
                     np.broadcast_to(np.sin(p)[None, :], (17, 6))], -1)
    surf = sd.shapes.from_points(grid, cells=(8, 3), knots=("periodic", "open"),
                                 domain=((0, 2 * np.pi), (0, np.pi / 2)))
    assert surf.fit_error < 0.05


def test_complex_input_is_refused_not_truncated():
    u = np.linspace(0.0, 1.0, 6)
    grid = np.stack(np.broadcast_arrays(u[:, None], u[None, :], 0.0 * u[:, None]), -1)
    with pytest.raises(InputError, match="complex"):
        sd.shapes.from_points(grid + 1j, cells=2, degree=2)
    with pytest.raises(InputError, match="complex"):
        sd.shapes.from_function(lambda a, b: np.stack([a, b, 1j * a], -1), cells=2, degree=2)
    surf = sd.shapes.plane(cells=2, degree=2)
    with pytest.raises(InputError, match="complex"):
        sd.Surface(surf.control_points + 0j, surf.basis_u, surf.basis_v)


# -- values the solvers cannot carry ---------------------------------------------------------
@pytest.mark.parametrize("material, key", [
    (dict(w10=1e308, w01=1.0), "material.w10"),
    (dict(mass=1e-320, w10=1.0, w01=1.0), "material.mass"),
    (dict(mass=1e-200, w10=1e100, w01=1.0), "material.mass"),  # λ ~ 1e300, mass the more extreme
    (dict(mass=1e-100, w10=1e200, w01=1.0), "material.w10"),
])
def test_material_scales_beyond_double_range_are_refused_naming_the_key(material, key):
    surf = sd.shapes.plane(cells=3)
    with pytest.raises(InputError, match=rf"^{key} = .*Rescale the units") as info:
        sd.Model(surf, sd.Material(**material), boundary="clamped")
    assert info.value.key == key


def test_no_free_coordinate_is_refused_at_the_model():
    surf = sd.shapes.plane(cells=1)
    with pytest.raises(InputError, match="no free coordinate: .* 4 x 4 control points"):
        sd.Model(surf, sd.Material(w10=1.0, w01=1.0), boundary="clamped")


def test_an_absurd_angular_frequency_is_refused():
    with pytest.raises(InputError, match=r"Harmonic.omega must be <= 1e\+12"):
        Harmonic(omega=1e300)


def test_a_huge_tessellation_is_refused_before_allocating():
    surf = sd.shapes.plane(cells=2, degree=2)
    with pytest.raises(InputError, match=r"tessellation resolution 1000000 asks for 1e\+12 vertices"):
        surf.tessellate(10**6)
    vertices, faces = surf.tessellate((2048, 2))      # the limit is on the product
    assert vertices.shape == (4096, 3) and faces.shape == (2 * 2047, 3)


def test_a_point_grid_of_strings_is_refused_not_parsed():
    with pytest.raises(InputError, match="real numbers, got dtype <U3"):
        sd.shapes.from_points(np.full((4, 4, 3), "1.5"), cells=1, degree=2)
