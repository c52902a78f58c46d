"""Payloads to JSON: dataclass or dict → JSON-ready dict, and a JSON Schema generated from it.

Convention (chosen for Foxglove's Plot panel, which plots any numeric path): records stay flat;
a fixed 3-float tuple (a `Vec3` such as `acc_b`, `pos_n`) becomes an `{"x","y","z"}` object and a
fixed 4-float tuple (a quaternion, w-x-y-z order) becomes `{"w","x","y","z"}`, so a plot path
reads `/vehicle/imu.acc_b.z`. Other tuples and lists stay arrays (`channels_us[2]`). Enums
become their value (an IntEnum its integer). Non-finite floats become null, since JSON has none.
"""

from __future__ import annotations

import dataclasses
import enum
import json
import math
import types
import typing
from collections.abc import Callable, Mapping
from operator import attrgetter, itemgetter
from typing import Any

VEC3_KEYS = ("x", "y", "z")
QUAT_KEYS = ("w", "x", "y", "z")

_HINTS_CACHE: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    """Resolved field type hints of a dataclass, cached per class."""
    hints = _HINTS_CACHE.get(cls)
    if hints is None:
        try:
            hints = typing.get_type_hints(cls)
        except (NameError, TypeError):
            hints = {}
        _HINTS_CACHE[cls] = hints
    return hints


def _fixed_float_tuple_len(hint: Any) -> int:
    """3 or 4 for `tuple[float, float, float(, float)]`, else 0."""
    if typing.get_origin(hint) is not tuple:
        return 0
    args = typing.get_args(hint)
    if len(args) in (3, 4) and all(a is float for a in args):
        return len(args)
    return 0


def to_jsonable(value: Any, hint: Any = None) -> Any:
    """Convert a payload value to plain JSON types following the module's conventions."""
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, bool | int | str) or value is None:
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return _converter(type(value))(value)
    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        n = _fixed_float_tuple_len(hint)
        if n and len(value) == n:
            keys = VEC3_KEYS if n == 3 else QUAT_KEYS
            return {k: to_jsonable(float(v)) for k, v in zip(keys, value, strict=True)}
        return [to_jsonable(v) for v in value]
    if isinstance(value, bytes | bytearray):
        return list(value)
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return to_jsonable(value.tolist())
    return str(value)


_PLAIN_TYPES = frozenset({int, float, str, bool, type(None)})
_CONVERTERS: dict[type, Callable[[Any], dict[str, Any]]] = {}


def _field_converter(hint: Any) -> Callable[[Any], Any]:
    """A per-field converter: plain values pass straight through (NaN is nulled at encoding)."""
    n = _fixed_float_tuple_len(hint)
    if n:
        keys = VEC3_KEYS if n == 3 else QUAT_KEYS

        def vec(v: Any) -> Any:
            if type(v) is tuple and len(v) == n:
                return dict(zip(keys, v, strict=True))
            return to_jsonable(v, hint)

        return vec

    def plain(v: Any) -> Any:
        return v if type(v) in _PLAIN_TYPES else to_jsonable(v, hint)

    return plain


def _converter(cls: type) -> Callable[[Any], dict[str, Any]]:
    """A dataclass → dict converter built once per class (the writer thread's hot path).

    The fields are fetched in one call and checked for plain values in one pass; only the 3-
    and 4-float tuples, and a value that is not plain, go through a converter of their own."""
    conv = _CONVERTERS.get(cls)
    if conv is None:
        hints = _hints(cls)
        names = tuple(f.name for f in dataclasses.fields(cls))
        fields = tuple((k, name, hints.get(name), _field_converter(hints.get(name)))
                       for k, name in enumerate(names))
        special = tuple((k, name, c) for k, name, hint, c in fields
                        if _fixed_float_tuple_len(hint))
        plain = tuple((k, name, hint) for k, name, hint, _ in fields
                      if not _fixed_float_tuple_len(hint))
        get: Callable[[object], tuple[Any, ...]] = (
            attrgetter(*names) if len(names) > 1
            else lambda o: tuple(getattr(o, name) for name in names))
        plain_get: Callable[[tuple[Any, ...]], tuple[Any, ...]] = (
            itemgetter(*(k for k, _, _ in plain)) if len(plain) > 1
            else (lambda v: tuple(v[k] for k, _, _ in plain)))

        def conv(obj: Any) -> dict[str, Any]:
            values = get(obj)
            out = dict(zip(names, values, strict=True))
            for k, name, c in special:
                out[name] = c(values[k])
            if not _PLAIN_TYPES.issuperset(map(type, plain_get(values))):
                for k, name, hint in plain:
                    if type(values[k]) not in _PLAIN_TYPES:
                        out[name] = to_jsonable(values[k], hint)
            return out

        _CONVERTERS[cls] = conv
    return conv


# json.dumps with any option builds a new encoder per call; the writer encodes every message
_COMPACT = json.JSONEncoder(separators=(",", ":"), allow_nan=False).encode


def encode_json(message: Mapping[str, Any]) -> bytes:
    """Compact UTF-8 JSON; a message that still holds a non-finite float has it nulled."""
    try:
        return _COMPACT(message).encode()
    except ValueError:
        return json.dumps(_null_non_finite(message), separators=(",", ":")).encode()


def _null_non_finite(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {k: _null_non_finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_null_non_finite(v) for v in value]
    return value


_NUMBER: dict[str, Any] = {"type": "number"}


def _schema_for_hint(hint: Any, value: Any) -> dict[str, Any]:
    """JSON Schema of one field from its type hint, falling back on its (JSON-ready) value.

    Only what Foxglove's JSON Schema reader accepts: one `type` per field (no `["number",
    "null"]`: a null still decodes, the schema only names the field's kind), objects always with
    `properties`, array items always typed.
    """
    origin = typing.get_origin(hint)
    if hint is bool:
        return {"type": "boolean"}
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        values = [m.value for m in hint]
        kind = "integer" if all(isinstance(v, int) for v in values) else "string"
        return {"type": kind, "enum": values, "description": hint.__name__}
    if hint is int:
        return {"type": "integer"}
    if hint is float:
        return dict(_NUMBER)
    if hint is str:
        return {"type": "string"}
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        return schema_for_dataclass(hint, value if isinstance(value, Mapping) else None)
    if origin is tuple or origin is list:
        n = _fixed_float_tuple_len(hint)
        if n:
            keys = VEC3_KEYS if n == 3 else QUAT_KEYS
            return {"type": "object", "properties": {k: dict(_NUMBER) for k in keys}}
        args = [a for a in typing.get_args(hint) if a is not Ellipsis]
        first = value[0] if isinstance(value, list) and value else None
        item = _schema_for_hint(args[0], first) if len(set(args)) == 1 else None
        return {"type": "array", "items": _array_item(item, first)}
    if origin in (typing.Union, types.UnionType):
        non_none = [a for a in typing.get_args(hint) if a is not type(None)]
        if len(non_none) == 1:
            return _schema_for_hint(non_none[0], value)
    return schema_for_value(value)


def _array_item(item: dict[str, Any] | None, first: Any) -> dict[str, Any]:
    """Foxglove reads arrays of scalars or objects only; anything else is described as text."""
    if item is None:
        item = schema_for_value(first)
    if item.get("type") in ("boolean", "string", "number", "integer", "object"):
        if item.get("type") == "string":
            item = {k: v for k, v in item.items() if k != "contentEncoding"}
        return item
    return {"type": "string", "description": "nested array"}


def schema_for_dataclass(cls: type, sample: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """JSON Schema (object) from a dataclass's field types; `sample` settles untyped fields."""
    hints = _hints(cls)
    props = {
        f.name: _schema_for_hint(hints.get(f.name), sample.get(f.name) if sample else None)
        for f in dataclasses.fields(cls)
    }
    schema: dict[str, Any] = {"type": "object", "title": cls.__name__, "properties": props}
    if cls.__doc__:
        schema["description"] = cls.__doc__.strip().splitlines()[0]
    return schema


def schema_for_value(value: Any) -> dict[str, Any]:
    """JSON Schema inferred from an already JSON-ready value (for dict payloads)."""
    if isinstance(value, bool):
        return {"type": "boolean"}
    if isinstance(value, int):
        return {"type": "integer"}
    if isinstance(value, float) or value is None:
        return dict(_NUMBER)
    if isinstance(value, str):
        return {"type": "string"}
    if isinstance(value, Mapping):
        return {
            "type": "object",
            "properties": {str(k): schema_for_value(v) for k, v in value.items()},
        }
    if isinstance(value, list):
        first = value[0] if value else None
        return {"type": "array", "items": _array_item(None, first)}
    return {"type": "string"}


def schema_for_payload(payload: Any, jsonable: Mapping[str, Any]) -> tuple[str, dict[str, Any]]:
    """(schema name, JSON Schema) for a topic's first payload."""
    if dataclasses.is_dataclass(payload) and not isinstance(payload, type):
        cls = type(payload)
        return f"{cls.__module__}.{cls.__qualname__}", schema_for_dataclass(cls, jsonable)
    schema = schema_for_value(dict(jsonable))
    return "", schema


def vector(value: Any) -> tuple[float, ...]:
    """Turn a recorded vector back into a tuple: an x/y/z (or w/x/y/z) object or a list."""
    if isinstance(value, Mapping):
        keys = QUAT_KEYS if "w" in value else VEC3_KEYS
        return tuple(float(value[k]) if value[k] is not None else math.nan for k in keys)
    return tuple(float(v) for v in value)


def _from_hint(hint: Any, value: Any) -> Any:
    if value is None:
        return math.nan if hint is float else None
    origin = typing.get_origin(hint)
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return hint(value)
    if hint is float:
        return float(value)
    if hint is int or hint is bool or hint is str:
        return value
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        return from_jsonable(hint, value)
    if origin is tuple:
        if isinstance(value, Mapping):
            return vector(value)
        args = [a for a in typing.get_args(hint) if a is not Ellipsis]
        item = args[0] if len(set(args)) == 1 else None
        return tuple(_from_hint(item, v) if item is not None else v for v in value)
    if origin in (typing.Union, types.UnionType):
        non_none = [a for a in typing.get_args(hint) if a is not type(None)]
        if len(non_none) == 1:
            return _from_hint(non_none[0], value)
    return value


def from_jsonable(cls: type, data: Mapping[str, Any]) -> Any:
    """Rebuild a dataclass record from its recorded dict (the inverse of `to_jsonable`).

    Vectors come back as tuples, enums as members, nulls in float fields as NaN; fields the
    recording lacks take the dataclass default (an error if there is none).
    """
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        raise TypeError(f"{cls!r} is not a dataclass")
    hints = _hints(cls)
    kwargs = {
        f.name: _from_hint(hints.get(f.name), data[f.name])
        for f in dataclasses.fields(cls)
        if f.name in data
    }
    return cls(**kwargs)
