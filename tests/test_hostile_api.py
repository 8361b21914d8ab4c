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
