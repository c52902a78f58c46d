"""Parameter dataclasses (station config, throttle curve) as JSON text and back, exactly.

The recording's message encoding turns non-finite floats into null, but a parameter such as an
unlimited setpoint slew (`inf`) must come back as itself for a rerun to fly the same controller,
so parameters travel as JSON text that keeps `Infinity`/`NaN` and every float's exact value.
"""

from __future__ import annotations

import dataclasses
import enum
import json
from typing import Any

from logs import from_jsonable


def _plain(value: Any) -> Any:
    if isinstance(value, enum.Enum):
        return value.value
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    return value


def dumps(params: Any) -> str:
    """JSON text of a (nested) parameter dataclass; enums as their values."""
    return json.dumps(_plain(params), separators=(",", ":"))


def loads(cls: type, text: str) -> Any:
    """Rebuild a parameter dataclass of type `cls` from `dumps` text (ValueError if it isn't)."""
    data = json.loads(text)
    if not isinstance(data, dict):
        raise ValueError(f"expected a JSON object for {cls.__name__}")
    try:
        return from_jsonable(cls, data)
    except (TypeError, KeyError) as exc:
        raise ValueError(f"not a {cls.__name__}: {exc}") from exc
