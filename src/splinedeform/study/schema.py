"""The sweep file as typed pydantic models: the one declaration of every key.

A sweep file names a base scenario and the axes of a design space::

    scenario = "plate.toml"          # relative to the sweep file

    [design]
    kind = "grid"                    # or "random", "latin-hypercube" (with n, seed)

    [[axis]]
    key = "material.w20"
    values = [0.5, 1.0, 2.0]

    [[axis]]
    key = "load[1].at"               # the first [[load]] table (counted from 1)
    values = [[0.5, 0.5], [0.25, 0.5]]

    [[axis]]
    key = "material.damping"
    range = [0.1, 10.0]
    count = 5
    scale = "log"

The reader (:mod:`.read`) checks each key with these models (through
:func:`splinedeform.scenario.checks.key_of`, as the scenario reader does), then the rules
tying keys together; ``splinedeform schema --sweep`` prints :func:`json_schema`.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Optional

from pydantic import BaseModel, ConfigDict, Field, Strict

from ..scenario.schema import Integer, Real, Text

#: the designs: every combination of the axes' values, or ``n`` points drawn at random
#: (uniformly, independently per axis) or by a Latin hypercube (one point per stratum)
DESIGNS = ("grid", "random", "latin-hypercube")
SCALES = ("linear", "log")
#: most cases one sweep may hold
MAX_CASES = 100_000

Count = Annotated[int, Strict(), Field(ge=1, le=MAX_CASES)]


class _Table(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Axis(_Table):
    """One ``[[axis]]``: a scenario key and the values it takes."""

    key: Text = Field(description=(
        "a key path of the base scenario: `material.w20`, `surface.cells`, `boundary.u0`, "
        "`solve.t_end`; `load[2].force` (or `load.2.force`) is a key of the second "
        "`[[load]]` table, `load.force` one of every `[[load]]` table"))
    values: Optional[Annotated[list[Any], Field(min_length=1, max_length=MAX_CASES)]] = Field(
        None, description="the values the key takes (any value the key allows)",
        json_schema_extra={"doc_default": "required unless `range`"})
    range: Optional[tuple[Real, Real]] = Field(
        None, title="[low, high]", description="an interval of numbers, `low < high`",
        json_schema_extra={"doc_default": "required unless `values`"})
    count: Optional[Count] = Field(
        None, description="grid: the number of equally spaced values of `range` (ends "
                          "included)", json_schema_extra={"doc_default": "required for "
                                                          "`range` on a grid"})
    scale: Literal[SCALES] = Field(  # type: ignore[valid-type]
        "linear", description="`range`: values equally spaced (linear) or equally spaced in "
                              "the logarithm (log, `low > 0`); random designs draw uniformly "
                              "in the same scale")
    integer: Annotated[bool, Strict()] = Field(
        False, description="`range`: values rounded to the nearest integer (for `surface.cells`)")


class Design(_Table):
    """``[design]``: how the axes' values are combined into cases."""

    kind: Literal[DESIGNS] = Field(  # type: ignore[valid-type]
        "grid", description="every combination of the axes' values (grid), or `n` points "
                            "drawn independently (random: Monte Carlo) or by a Latin "
                            "hypercube")
    n: Optional[Count] = Field(None, description="random, latin-hypercube: the number of cases",
                               json_schema_extra={"doc_default": "required for random designs"})
    seed: Integer = Field(0, description="random, latin-hypercube: the seed of the draw")


class SweepOutput(_Table):
    """``[output]``: what the sweep writes besides its tables and report."""

    cases: Annotated[bool, Strict()] = Field(
        False, description="write each case's outputs (the base scenario's `output.formats`) "
                           "to `cases/<hash>/`")
    plots: Annotated[bool, Strict()] = Field(
        True, description="plots of each result against each axis in `report.md`")


class SweepFile(_Table):
    """A sweep file: a base scenario and the axes of a design study (``docs/sweep.md``)."""

    model_config = ConfigDict(extra="forbid", title="splinedeform sweep")

    title: Text = Field("", description="one-line title, shown in the report")
    description: Text = Field("", description="free text, copied to the report")
    scenario: Text = Field(description="the base scenario file, relative to the sweep file")
    design: Design = Field(default_factory=Design)
    axis: Annotated[list[Axis], Field(min_length=1)] = Field(
        description="[[axis]] tables, one per key varied")
    output: SweepOutput = Field(default_factory=SweepOutput)


def json_schema() -> dict[str, Any]:
    """JSON Schema (draft 2020-12) of sweep files, generated from :class:`SweepFile`."""
    schema = SweepFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    return schema
