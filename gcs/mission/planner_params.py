"""The `[planner]` table of a mission file into the planners' frozen parameter dataclasses.

Keys named like a field of the planner's parameters set that field (lists become tuples,
strings become the field's enum); a few mission-level keys (`max_steps`, `seed`, ...) are kept
apart. Anything else, or a value the planner rejects, is a one-line UsageError naming the file.
"""

from __future__ import annotations

import dataclasses
import enum
import types
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gcs.errors import UsageError
from gcs.mission.spec import MissionSpec, PlannerKind
from planners.epbha.planner import EpbhaParams
from planners.flocking.formation import FormationParams
from planners.flocking.planner import FlockParams
from planners.radiation import RadiationMapperParams

MISSION_KEYS: dict[str, type] = {
    "max_steps": int,  # planner steps before the mission gives up
    "seed": int,  # seed of the kinematic world's sensor noise
    "noise_sigma_m": float,  # IR noise of the kinematic world (the SITL's own is in its world)
    "max_samples": int,  # radiation: sample budget
    "floor_margin_m": float,  # radiation: keep the mapping area this far inside the room walls
    "min_iou": float,  # radiation: the found contour must overlap the true one this much
}


@dataclass(frozen=True, slots=True)
class PlannerSetup:
    """The planner's parameters plus the mission-level keys of the `[planner]` table."""

    params: Any
    max_steps: int
    seed: int
    noise_sigma_m: float
    max_samples: int
    floor_margin_m: float
    min_iou: float


def _convert(value: Any, hint: Any, where: str) -> Any:
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin in (typing.Union, types.UnionType) and type(None) in args:
        # TOML has no null: an optional parameter given is a value of its other type
        (inner,) = (a for a in args if a is not type(None))
        return _convert(value, inner, where)
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        try:
            return hint(value)
        except ValueError:
            allowed = ", ".join(str(m.value) for m in hint)
            raise UsageError(f"{where}: expected one of {allowed}, got {value!r}") from None
    if hint is float and isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    if hint is int and isinstance(value, int) and not isinstance(value, bool):
        return value
    if hint is bool and isinstance(value, bool):
        return value
    if origin is tuple and isinstance(value, list):
        return tuple(float(v) if isinstance(v, int | float) else v for v in value)
    raise UsageError(f"{where}: expected {getattr(hint, '__name__', hint)}, got {value!r}")


def _build(cls: type, table: dict[str, Any], path: Path, nested: dict[str, type] | None = None
           ) -> Any:
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    kwargs: dict[str, Any] = {}
    sub: dict[str, dict[str, Any]] = {}
    nested = nested or {}
    for key, value in table.items():
        where = f"{path}: planner.{key}"
        if key in names and key not in nested:
            kwargs[key] = _convert(value, hints[key], where)
            continue
        for field_name, sub_cls in nested.items():
            sub_names = {f.name for f in dataclasses.fields(sub_cls)}
            if key in sub_names:
                sub_hints = typing.get_type_hints(sub_cls)
                sub.setdefault(field_name, {})[key] = _convert(value, sub_hints[key], where)
                break
        else:
            allowed = sorted(names - set(nested) | set(MISSION_KEYS)
                             | {n for c in nested.values() for n in
                                (f.name for f in dataclasses.fields(c))})
            raise UsageError(f"{where}: unknown parameter; expected one of {', '.join(allowed)}")
    for field_name, sub_cls in nested.items():
        if field_name in sub:
            # the planner's own defaults for the nested table (the flock's leader keeps off
            # farther than EPBHA alone), with the mission's keys over them
            default = next((f.default_factory() for f in dataclasses.fields(cls)
                            if f.name == field_name and callable(f.default_factory)),
                           sub_cls())
            try:
                kwargs[field_name] = dataclasses.replace(default, **sub[field_name])
            except ValueError as exc:
                raise UsageError(f"{path}: planner: {exc}") from None
    try:
        return cls(**kwargs)
    except (ValueError, TypeError) as exc:
        raise UsageError(f"{path}: planner: {exc}") from None


def planner_setup(spec: MissionSpec, room_min_n: tuple[float, float] | None = None,
                  room_max_n: tuple[float, float] | None = None) -> PlannerSetup:
    """Build the planner's parameters from the mission's `[planner]` table."""
    table = dict(spec.planner_params)
    mission: dict[str, Any] = {}
    for key, typ in MISSION_KEYS.items():
        if key in table:
            mission[key] = _convert(table.pop(key), typ, f"{spec.path}: planner.{key}")
    margin = float(mission.get("floor_margin_m", 0.5))
    params: Any
    if spec.planner is PlannerKind.EPBHA:
        params = _build(EpbhaParams, table, spec.path)
    elif spec.planner is PlannerKind.FLOCKING:
        params = _build(FlockParams, table, spec.path,
                        {"formation": FormationParams, "epbha": EpbhaParams})
    else:
        if room_min_n is not None and room_max_n is not None:
            for key, value in (("x_min_m", room_min_n[0] + margin),
                               ("y_min_m", room_min_n[1] + margin),
                               ("x_max_m", room_max_n[0] - margin),
                               ("y_max_m", room_max_n[1] - margin)):
                table.setdefault(key, value)
        params = _build(RadiationMapperParams, table, spec.path)
    return PlannerSetup(
        params=params,
        max_steps=int(mission.get("max_steps", 2000)),
        seed=int(mission.get("seed", 1)),
        noise_sigma_m=float(mission.get("noise_sigma_m", 0.01)),
        max_samples=int(mission.get("max_samples", 400)),
        floor_margin_m=margin,
        min_iou=float(mission.get("min_iou", 0.5)),
    )
