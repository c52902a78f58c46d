"""TOML tables a run is made of: the world's and the station's, with a campaign's axes applied.

A run varies a world file and a station file the way a user would edit them: an axis
`world.sensors.sonar.noise_m` sets that key in the world file's table, `station.altitude.gains.kp`
in the station file's. The tables go to the SITL's and the station's own loaders, which check
them as they check files. `dumps` writes a station table back as a file `fly --config` reads.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gcs.foxglove_feed import DEFAULT_WORLD
from sitl import lockstep as sitl_lockstep
from worldfile import read_toml


def set_dotted(table: dict[str, Any], dotted: str, value: Any) -> dict[str, Any]:
    """`table` with `a.b.c = value` set (tables created on the way); returns `table`."""
    keys = dotted.split(".")
    node = table
    for k in keys[:-1]:
        node = node.setdefault(k, {})
        if not isinstance(node, dict):
            raise ValueError(f"{dotted}: {k} is a value, not a table")
    node[keys[-1]] = value
    return table


def merged(base: Mapping[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    """A deep copy of `base` with the tables of `over` merged in (values replace)."""
    out = copy.deepcopy(dict(base))
    for k, v in over.items():
        if isinstance(v, Mapping) and isinstance(out.get(k), dict):
            out[k] = merged(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def read_table(path: Path) -> dict[str, Any]:
    """A TOML file's table (TomlFileError, a ValueError of one line, when it cannot be read)."""
    return read_toml(path)


def world_table(world: Path | None, over: Mapping[str, Any]) -> dict[str, Any]:
    """The world file's table (the empty room when None) with `over` merged in."""
    return merged(read_table(world if world is not None else DEFAULT_WORLD), over)


def check_world(table: Mapping[str, Any]) -> None:
    """Let the SITL's world loader judge a table (ValueError, one line, when it refuses)."""
    sitl_lockstep.world_of(table)


def check_faults(faults: Mapping[str, Any]) -> None:
    """Let the SITL judge a link-fault table (ValueError or TypeError, one line)."""
    sitl_lockstep.LinkFaults(**faults)


def station_table(config: Path | None, over: Mapping[str, Any]) -> dict[str, Any]:
    """The station file's table (empty when None) with `over` merged in."""
    return merged(read_table(config) if config is not None else {}, over)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def dumps(table: Mapping[str, Any], header: str = "") -> str:
    """TOML text of nested tables of numbers, strings, booleans and lists."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]

    def emit(node: Mapping[str, Any], prefix: str) -> None:
        plain = [(k, v) for k, v in node.items() if not isinstance(v, Mapping)]
        if prefix and plain:
            lines.append(f"\n[{prefix}]")
        for k, v in plain:
            lines.append(f"{k} = {_value(v)}")
        for k, v in node.items():
            if isinstance(v, Mapping):
                emit(v, f"{prefix}.{k}" if prefix else k)

    emit(table, "")
    return "\n".join(lines).lstrip("\n") + "\n"
