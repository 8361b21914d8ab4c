"""The JSON Schema of scenario files: generated from the pydantic models, valid for every
example, refusing what the reader refuses, and in agreement with the reader's keys."""

import json
import tomllib
from pathlib import Path

import pytest

jsonschema = pytest.importorskip("jsonschema")
schema_module = pytest.importorskip("splinedeform.scenario.schema")

from splinedeform.scenario.keys import (BOUNDARY_KEYS, FREE_REGION_KEYS,  # noqa: E402
                                        LOAD_KEYS, LOAD_KIND_KEYS, MATERIAL_KEYS, OUTPUT_KEYS,
                                        PROFILE_KEYS, SHAPE_PARAMETERS, SOLVE_KEYS,
                                        SOLVE_KIND_KEYS, SURFACE_KEYS, TOP_KEYS)

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = sorted((ROOT / "examples").glob("*.toml")) + [ROOT / "src/splinedeform/data/demo.toml"]


@pytest.fixture(scope="module")
def validator():
    schema = schema_module.json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.name)
def test_every_example_is_valid_against_the_schema(path, validator):
    errors = list(validator.iter_errors(tomllib.loads(path.read_text())))
    assert not errors, [f"{'.'.join(map(str, e.path))}: {e.message}" for e in errors]


@pytest.mark.parametrize("change, where", [
    (("material", "w10", -1.0), "material"),
    (("surface", "radius", 2.0), "surface"),          # not a parameter of a plane
    (("solve", "t_end", 1e308), "solve"),
    (("solve", "function_samples", 0), "solve"),
    (("output", "formats", ["pdf"]), "output"),
    (("material", "colour", "red"), "material"),
])
def test_the_schema_refuses_what_the_reader_refuses(change, where, validator):
    from splinedeform import ScenarioError
    from splinedeform.scenario import parse_scenario

    raw = tomllib.loads((ROOT / "examples" / "plane_overdamped_step.toml").read_text())
    table, key, value = change
    raw[table][key] = value
    assert list(validator.iter_errors(raw)), change
    text = "\n".join(f"[{t}]\n" + "\n".join(f"{k} = {json.dumps(v)}" for k, v in tab.items())
                     for t, tab in raw.items() if isinstance(tab, dict))
    text += '\n[[load]]\nkind = "point"\nat = [0.5, 0.5]\nforce = [0.0, 0.0, -1.0]\n'
    with pytest.raises(ScenarioError, match=rf": {where}"):
        parse_scenario(text)


def fields(model, without=()) -> dict:
    return {name: f.default for name, f in model.model_fields.items() if name not in without}


def same_defaults(model_fields: dict, keys: dict, names) -> None:
    for name in names:
        documented = keys[name].default if hasattr(keys[name], "default") else keys[name]
        given = model_fields[name]
        if isinstance(given, list):
            given = tuple(given)
        if documented in (None,) or given is None or repr(given).startswith("PydanticUndefined"):
            continue
        if isinstance(documented, tuple) and len(documented) == 2 and documented[0] == \
                documented[1] and not isinstance(given, tuple):
            documented = documented[0]                  # scalar_or_pair default (1.0, 1.0)
        assert given == documented, (name, given, documented)


def test_models_and_reader_keys_agree_key_for_key():
    S = schema_module
    assert set(fields(S.ScenarioFile)) == set(TOP_KEYS) | {"surface", "material", "boundary",
                                                            "load", "solve", "output"}
    fitted = set(fields(S._Fitted))
    for model in S.SHAPE_MODELS:
        shape = model.model_fields["shape"].annotation.__args__[0]
        own = fields(model, without=fitted | {"shape"})
        expected = set(SHAPE_PARAMETERS[shape]) | {"file": {"path", "frame"},
                                                   "cad": {"path"}}.get(shape, set())
        assert set(own) == expected, shape
        same_defaults(own, {**SHAPE_PARAMETERS[shape], **SURFACE_KEYS}, own)
    assert {m.model_fields["shape"].annotation.__args__[0] for m in S.SHAPE_MODELS} == \
        set(SHAPE_PARAMETERS)
    assert fitted | {"shape", "path", "frame"} == set(SURFACE_KEYS)
    same_defaults(fields(S._Fitted), SURFACE_KEYS, fitted)
    for model, keys in ((S.Material, MATERIAL_KEYS), (S.Boundary, BOUNDARY_KEYS),
                        (S.FreeRegion, FREE_REGION_KEYS), (S.Output, OUTPUT_KEYS)):
        assert set(fields(model)) == set(keys), model.__name__
        same_defaults(fields(model), keys, keys)
    profile = fields(S._Profiled)
    assert set(profile) == {"profile"} | {k for ks in PROFILE_KEYS.values() for k in ks}
    same_defaults(profile, LOAD_KEYS, profile)
    on_face = fields(S._OnFace, without=set(profile))     # face: optional for every kind
    assert set(on_face) == {"face"}
    same_defaults(on_face, LOAD_KEYS, on_face)
    for model in S.LOAD_MODELS:
        kind = model.model_fields["kind"].annotation.__args__[0]
        assert set(fields(model, without=set(profile) | {"kind", "face"})) == \
            set(LOAD_KIND_KEYS[kind])
        assert "face" in model.model_fields
    for model in S.SOLVE_MODELS:
        kind = model.model_fields["kind"].annotation.__args__[0]
        own = fields(model, without={"kind"})
        assert set(own) == set(SOLVE_KIND_KEYS[kind]), kind
        same_defaults(own, SOLVE_KEYS, own)


def test_the_command_prints_the_schema():
    typer_testing = pytest.importorskip("typer.testing")
    from splinedeform import cli

    result = typer_testing.CliRunner().invoke(cli.app, ["schema"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.output) == json.loads(json.dumps(schema_module.json_schema()))


def test_the_key_reference_of_the_docs_is_generated_from_the_models():
    from splinedeform.scenario import reference

    text = (ROOT / "docs" / "scenario.md").read_text(encoding="utf-8")
    assert sorted(reference.blocks(text)) == sorted(reference.tables())
    assert reference.update(text) == text, (
        "docs/scenario.md differs from the models: run "
        "python -m splinedeform.scenario.reference docs/scenario.md")


def test_the_reference_follows_a_changed_description(monkeypatch):
    from splinedeform.scenario import keys, reference

    text = (ROOT / "docs" / "scenario.md").read_text(encoding="utf-8")
    changed = dict(keys.MATERIAL_KEYS)
    changed["mass"] = type(changed["mass"])(changed["mass"].check, 2.0, "heavier")
    monkeypatch.setattr(reference, "MATERIAL_KEYS", changed)
    assert "| `material.mass` | a number > 0 | `2.0` | heavier |" in reference.update(text)


def test_the_editor_example_of_the_docs_is_a_valid_scenario(validator):
    import re

    from splinedeform.scenario import parse_scenario

    text = (ROOT / "docs" / "scenario.md").read_text(encoding="utf-8")
    blocks = [b for b in re.findall(r"```toml\n(.*?)```", text, re.S) if "#:schema" in b]
    assert blocks, "docs/scenario.md shows no #:schema line"
    for block in blocks:
        assert block.startswith("#:schema ")          # taplo reads it on the first line only
        assert not list(validator.iter_errors(tomllib.loads(block)))
        assert parse_scenario(block).solve.kind == "modes"


def test_the_reference_writer_names_a_missing_file_and_rewrites_a_copy(tmp_path, capsys):
    """``python -m splinedeform.scenario.reference FILE``: a file it cannot read is named
    with exit code 2 and nothing written; a copy of the docs is rewritten whole, equal."""
    from pathlib import Path

    from splinedeform.scenario import reference

    assert reference.main([str(tmp_path / "missing.md")]) == 2
    assert "missing.md: Markdown file not found" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
    text = Path("docs/scenario.md").read_text(encoding="utf-8")
    copy = tmp_path / "scenario.md"
    copy.write_text(text, encoding="utf-8")
    assert reference.main([str(copy)]) == 0
    assert copy.read_text(encoding="utf-8") == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.md"]    # no temporaries
