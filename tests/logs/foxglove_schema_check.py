"""What Foxglove's JSON Schema reader accepts, as a checker (its rules, restated here).

Foxglove turns a channel's JSON Schema into message definitions and gives up on the whole topic
at the first field it cannot map: the root and every nested object need `"type": "object"` and a
`properties` map; each field needs one `type` of boolean, string (plain or base64), number,
integer, object or array; array items must be boolean, plain string, number, integer or object.
"""

from __future__ import annotations

from typing import Any

_SCALARS = {"boolean", "string", "number", "integer"}


def foxglove_schema_problems(schema: Any, path: str = "") -> list[str]:
    """Every reason Foxglove would refuse this object schema (empty when it reads it)."""
    where = path or "<root>"
    if not isinstance(schema, dict) or schema.get("type") != "object":
        return [f"{where}: expected type object, got {schema!r:.60}"]
    props = schema.get("properties")
    if not isinstance(props, dict):
        return [f"{where}: object without properties"]
    problems: list[str] = []
    for name, field in props.items():
        here = f"{path}.{name}" if path else name
        if not isinstance(field, dict):
            problems.append(f"{here}: not a schema")
            continue
        kind = field.get("type")
        if not isinstance(kind, str):
            problems.append(f"{here}: type must be one string, got {kind!r}")
        elif kind == "string":
            if field.get("contentEncoding") not in (None, "base64"):
                problems.append(f"{here}: contentEncoding {field['contentEncoding']!r}")
        elif kind in _SCALARS:
            continue
        elif kind == "object":
            problems += foxglove_schema_problems(field, here)
        elif kind == "array":
            item = field.get("items")
            item_kind = item.get("type") if isinstance(item, dict) else None
            if not isinstance(item_kind, str):
                problems.append(f"{here}: array items of type {item_kind!r}")
            elif item_kind == "object":
                problems += foxglove_schema_problems(item, here + "[]")
            elif item_kind not in _SCALARS:
                problems.append(f"{here}: array items of type {item_kind!r}")
            elif item_kind == "string" and item.get("contentEncoding") is not None:
                problems.append(f"{here}: array of encoded strings")
        else:
            problems.append(f"{here}: unsupported type {kind!r}")
    return problems
