"""The page's messages are strict: each field takes its own JSON type and nothing else.

``mass: true`` is no mass of 1, ``w10: "1"`` no weight, ``index: true`` or ``1.5`` no index;
each is refused naming the field and the type received (never the value itself).
"""

from __future__ import annotations

import json

import pytest
from pydantic import ValidationError

from splinedeform.sculpt.messages import (CorrectionMessage, ResolveMessage, SaveMessage,
                                          describe_error)

GOOD = {"material": {"mass": 1.0, "damping": 0.5, "w10": 1, "w01": 1.0},
        "boundary": {"u0": "clamped"}, "free_points": [[1, 2], [2, 2]]}
PUSH = {"index": 3, "force": [0, 0.5, -1], "t_on": 0, "t_off": 0.5}


def _refusal(model, data) -> str:
    with pytest.raises(ValidationError) as info:
        model.model_validate(json.loads(json.dumps(data)))     # as the server reads it
    return describe_error(info.value)


def test_well_typed_messages_pass_and_integers_are_numbers():
    message = ResolveMessage.model_validate(json.loads(json.dumps(GOOD)))
    assert message.material.w10 == 1.0 and isinstance(message.material.w10, float)
    assert message.free_points == [(1, 2), (2, 2)]
    save = SaveMessage.model_validate({"version": 1, "t_end": 2, "pushes": [PUSH]})
    assert save.pushes[0].force == (0.0, 0.5, -1.0)


@pytest.mark.parametrize("field, value, where, got", [
    ("mass", True, "material.mass", "true/false"),
    ("mass", False, "material.mass", "true/false"),
    ("w10", "1", "material.w10", "a string"),
    ("damping", None, "material.damping", "null"),
    ("w02", [1.0], "material.w02", "an array"),
])
def test_a_material_weight_of_another_type_is_refused(field, value, where, got):
    data = {**GOOD, "material": {**GOOD["material"], field: value}}
    text = _refusal(ResolveMessage, data)
    assert text.startswith(where + ":") and f"(got {got})" in text


@pytest.mark.parametrize("data, where, got", [
    ({**GOOD, "free_points": [[True, 2]]}, "free_points.0.0", "true/false"),
    ({**GOOD, "free_points": [[1.5, 2]]}, "free_points.0.0", "a number"),
    ({**GOOD, "free_points": [["1", 2]]}, "free_points.0.0", "a string"),
    ({**GOOD, "free_region": {"u": [True, 0.5]}}, "free_region.u.0", "true/false"),
    ({**GOOD, "boundary": {"u0": True}}, "boundary.u0", "true/false"),
])
def test_indices_regions_and_edges_of_another_type_are_refused(data, where, got):
    text = _refusal(ResolveMessage, data)
    assert text.startswith(where + ":") and f"(got {got})" in text


@pytest.mark.parametrize("push, where", [
    ({**PUSH, "index": True}, "pushes.0.index"),
    ({**PUSH, "index": 3.0}, "pushes.0.index"),
    ({**PUSH, "force": [0, "1", 0]}, "pushes.0.force.1"),
    ({**PUSH, "force": [0, False, 0]}, "pushes.0.force.1"),
    ({**PUSH, "t_on": "0"}, "pushes.0.t_on"),
])
def test_a_push_of_another_type_is_refused(push, where):
    text = _refusal(SaveMessage, {"version": 1, "t_end": 1.0, "pushes": [push]})
    assert text.startswith(where + ":")
    assert _refusal(SaveMessage, {"version": True, "t_end": 1.0, "pushes": [PUSH]}) \
        .startswith("version:")
    assert _refusal(CorrectionMessage, {"version": 1, "index": "4"}).startswith("index:")


def test_the_value_itself_is_not_echoed():
    text = _refusal(ResolveMessage, {**GOOD, "material": {"w10": "<img src=x>"}})
    assert "<img" not in text and "material.w10" in text
