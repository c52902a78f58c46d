"""Validate JSON messages against Foxglove's official JSON Schemas (`@foxglove/schemas` 2.1.0).

The schemas live in `shared/fixtures/foxglove-jsonschema/` beside the checkout (one file per
well-known type, `SceneUpdate.json` for `foxglove.SceneUpdate`); they are read, never edited.
"""

from __future__ import annotations

import json
from collections import Counter
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft7Validator
from mcap.reader import make_reader

from tests.fixture_paths import FOXGLOVE_SCHEMAS


def require_schemas() -> Path:
    """The schema folder, or skip the test when the fixtures are not beside the checkout."""
    if not (FOXGLOVE_SCHEMAS / "SceneUpdate.json").is_file():
        pytest.skip(f"Foxglove's schemas {FOXGLOVE_SCHEMAS} are not here "
                    "(they come with ../shared/fixtures)")
    return FOXGLOVE_SCHEMAS


@cache
def validator(schema_name: str) -> Draft7Validator:
    """The official validator of a `foxglove.X` schema name."""
    path = require_schemas() / f"{schema_name.removeprefix('foxglove.')}.json"
    return Draft7Validator(json.loads(path.read_text(encoding="utf-8")))


def problems(schema_name: str, message: Any) -> list[str]:
    """Why the official schema refuses this message (empty when it validates)."""
    return [f"{'/'.join(map(str, e.absolute_path)) or '<root>'}: {e.message}"
            for e in validator(schema_name).iter_errors(message)]


def check_recording(path: Path) -> Counter[str]:
    """Validate every `foxglove.*` message of an MCAP file; how many there were per topic.

    Fails on the first message the official schema refuses, naming topic, time and reason.
    """
    counts: Counter[str] = Counter()
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
            if schema is None or not schema.name.startswith("foxglove."):
                continue
            found = problems(schema.name, json.loads(message.data))
            assert not found, (f"{path.name} {channel.topic} at {message.log_time} "
                               f"({schema.name}): {found[:3]}")
            counts[channel.topic] += 1
    return counts
