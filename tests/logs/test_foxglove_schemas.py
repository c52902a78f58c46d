"""Every schema a recording carries is one Foxglove's JSON Schema reader accepts."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

from mcap.reader import make_reader

from logs import Recorder
from logs.foxglove import WELL_KNOWN_SCHEMAS
from logs.recorder import RAW_FRAME_SCHEMA
from tests.logs.foxglove_schema_check import foxglove_schema_problems


def _schemas_in(path) -> dict[str, dict]:
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    return {s.name: json.loads(s.data) for s in summary.schemas.values()}


def test_the_checker_catches_what_foxglove_refuses() -> None:
    good = {"type": "object", "properties": {"a": {"type": "number"}}}
    assert foxglove_schema_problems(good) == []
    assert foxglove_schema_problems(
        {"type": "object", "properties": {"a": {"type": ["number", "null"]}}}
    )
    assert foxglove_schema_problems({"type": "object", "properties": {"a": {"type": "object"}}})
    assert foxglove_schema_problems(
        {"type": "object", "properties": {"a": {"type": "array", "items": {}}}}
    )


def test_well_known_and_raw_frame_schemas() -> None:
    for name, schema in {**WELL_KNOWN_SCHEMAS, "raw": RAW_FRAME_SCHEMA}.items():
        assert foxglove_schema_problems(schema) == [], name


def test_every_schema_of_a_recorded_flight(recorded_flight) -> None:
    path, _ = recorded_flight
    schemas = _schemas_in(path)
    assert len(schemas) >= 10
    for name, schema in schemas.items():
        assert foxglove_schema_problems(schema) == [], name


@dataclass(frozen=True)
class Awkward:
    """Fields whose types need care: optional, untyped, nested, dict, empty list."""

    maybe_m: float | None
    anything: Any
    table: dict[str, float]
    empty: list[int] = field(default_factory=list)
    grid: list[list[float]] = field(default_factory=list)
    pairs: tuple[int, str] = (1, "a")


def test_awkward_payloads_still_give_readable_schemas(tmp_path) -> None:
    with Recorder(tmp_path / "a.mcap", metadata={}) as rec:
        rec.put("/awkward", 1.0, Awkward(None, {"k": [1, 2]}, {"x": 1.0}, [], [[1.0]]))
        rec.put("/dict", 1.0, {"none": None, "empty": [], "nested": {"deep": {}}, "ll": [[1]]})
    for name, schema in _schemas_in(rec.path).items():
        assert foxglove_schema_problems(schema) == [], name
