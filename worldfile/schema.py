"""The world file: a room, what stands in it and where the vehicles start.

World files are TOML. Coordinates in the FILE are "x north, y east, z up" in metres with z = 0
on the floor, because heights are what people measure; this module converts them to local NED
(z down) once, for every reader (the simulator and the station). Top-level keys:

    name = "table_room"                                      # default: the file's stem
    [room]       min = [x, y, z_up], max = [x, y, z_up]      # the room's inside extents
    [[boxes]]    name = "...", min = [x, y, z_up], max = [x, y, z_up]
    [[floor]]    name = "...", material = "carpet", min = [x, y], max = [x, y]
    [[sources]]  name = "...", position = [x, y, z_up], strength_cps = 5000.0  # counts/s at 1 m
    [radiation]  background_cps = 50.0    # default: 1 % of the strongest source
    [mocap]      enabled = true
    start_positions = [[x, y], [x, y, z_up], ...]   # no z_up: on top of what stands there
    [origin]     lat_deg = ..., lon_deg = ..., alt_amsl_m = ...
    [sensors], [vehicle], [autopilot]               # the simulator's own tables, kept raw here

An `[x, y]` start stands on top of the highest box below it, else on the floor: a vehicle put
down over a box rests on it, and the simulator and the station's kinematic runs must agree.

A bad file raises WorldFileError with one line: `<file>: <field>: <problem>`.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from worldfile.toml_file import read_toml

Vec3 = tuple[float, float, float]
Vec2 = tuple[float, float]

SIMULATOR_TABLES = ("sensors", "vehicle", "autopilot")
"""Tables the simulator reads itself (its sensors, airframe and autopilot options)."""


class FieldError(ValueError):
    """A field of a world table is invalid; the message starts with the field's name."""


class WorldFileError(ValueError):
    """A world file is missing, unreadable or invalid; the message is one line."""


class FloorMaterial(enum.Enum):
    """What the floor is made of under a patch; carpet swallows and delays sonar echoes."""

    HARD = "hard"
    CARPET = "carpet"


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned solid box, corners in NED (min_n[i] < max_n[i])."""

    name: str
    min_n: Vec3
    max_n: Vec3

    @property
    def top_z_n(self) -> float:
        """NED z of the top face (the smallest z)."""
        return self.min_n[2]


@dataclass(frozen=True, slots=True)
class FloorPatch:
    """A rectangle of floor (north/east extents) made of `material`."""

    name: str
    material: FloorMaterial
    min_ne: Vec2
    max_ne: Vec2

    def contains(self, north_m: float, east_m: float) -> bool:
        """True when (north, east) lies on the patch."""
        return (
            self.min_ne[0] <= north_m <= self.max_ne[0]
            and self.min_ne[1] <= east_m <= self.max_ne[1]
        )


@dataclass(frozen=True, slots=True)
class RadiationSource:
    """A point source: counts/s a detector at 1 m would see."""

    name: str
    pos_n: Vec3
    strength_cps: float


@dataclass(frozen=True, slots=True)
class GeoOrigin:
    """Where NED (0, 0, 0) is on Earth (the floor at the origin).

    The default is 0° N 0° E, not the thesis's lab (JAIST, 36.4446° N 136.5927° E): the vehicle
    has no GPS, so the location is only a label, but ground truth leaves the SITL as SIM_STATE,
    whose MAVLink 1 payload has latitude/longitude as float32 degrees (the int32 fields are
    MAVLink 2 extensions). A float32 resolves 0.4 m × 1.4 m at JAIST and well under a millimetre
    within a few kilometres of 0° N 0° E, so truth positions stay exact on both profiles.
    """

    lat_deg: float = 0.0
    lon_deg: float = 0.0
    alt_amsl_m: float = 60.0


@dataclass(frozen=True, slots=True)
class WorldSpec:
    """A world file's content in local NED metres; the simulator's own tables kept raw."""

    name: str
    room_min_n: Vec3  # z: the ceiling
    room_max_n: Vec3  # z: the floor
    boxes: tuple[Box, ...] = ()
    carpets: tuple[FloorPatch, ...] = ()
    sources: tuple[RadiationSource, ...] = ()
    background_cps: float = 0.0
    mocap_enabled: bool = True
    start_positions_n: tuple[Vec3, ...] = ((0.0, 0.0, 0.0),)
    origin: GeoOrigin = field(default_factory=GeoOrigin)
    simulator: Mapping[str, Any] = field(default_factory=dict)  # sensors, vehicle, autopilot

    @property
    def floor_z_n(self) -> float:
        """NED z of the floor."""
        return self.room_max_n[2]


_TOP_KEYS = {"name", "room", "boxes", "floor", "sources", "radiation", "mocap",
             "start_positions", "origin", *SIMULATOR_TABLES}


def table(data: object, where: str, allowed: set[str]) -> Mapping[str, Any]:
    """`data` as a table whose keys are all in `allowed` (FieldError otherwise)."""
    if not isinstance(data, Mapping):
        raise FieldError(f"{where}: expected a table, got {type(data).__name__}")
    for key in data:
        if key not in allowed:
            raise FieldError(f"{where}.{key}: unknown field (known: {', '.join(sorted(allowed))})")
    return data


def _require(data: Mapping[str, Any], key: str, where: str) -> Any:
    if key not in data:
        raise FieldError(f"{where}.{key}: missing")
    return data[key]


def number(value: object, where: str) -> float:
    """A finite number (not a bool) as a float (FieldError otherwise)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise FieldError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _numbers(value: object, n: int, where: str) -> tuple[float, ...]:
    if not isinstance(value, list | tuple):
        raise FieldError(f"{where}: expected {n} numbers, got {type(value).__name__}")
    if len(value) != n:
        raise FieldError(f"{where}: expected {n} numbers, got {len(value)}")
    return tuple(number(v, f"{where}[{i}]") for i, v in enumerate(value))


def _name(data: Mapping[str, Any], where: str) -> str:
    name = _require(data, "name", where)
    if not isinstance(name, str) or not name.strip():
        raise FieldError(f"{where}.name: expected a non-empty string, got {name!r}")
    return name


def _up_to_ned(p: tuple[float, ...]) -> Vec3:
    return (p[0], p[1], 0.0 - p[2])


def _ordered(lo: tuple[float, ...], hi: tuple[float, ...], where: str) -> None:
    for i, (a, b) in enumerate(zip(lo, hi, strict=True)):
        if not a < b:
            raise FieldError(f"{where}.max[{i}]: must be greater than min[{i}] ({a}), got {b}")


def _parse_box(data: object, where: str, room: tuple[Vec3, Vec3]) -> Box:
    t = table(data, where, {"name", "min", "max"})
    name = _name(t, where)
    lo = _numbers(_require(t, "min", where), 3, f"{where}.min")
    hi = _numbers(_require(t, "max", where), 3, f"{where}.max")
    _ordered(lo, hi, where)
    min_n = (lo[0], lo[1], 0.0 - hi[2])
    max_n = (hi[0], hi[1], 0.0 - lo[2])
    rmin, rmax = room
    for i in range(3):
        if max_n[i] <= rmin[i] or min_n[i] >= rmax[i]:
            raise FieldError(f"{where}: lies entirely outside the room")
    return Box(name=name, min_n=min_n, max_n=max_n)


def _parse_patch(data: object, where: str) -> FloorPatch:
    t = table(data, where, {"name", "material", "min", "max"})
    name = _name(t, where)
    material = _require(t, "material", where)
    try:
        mat = FloorMaterial(material)
    except ValueError:
        known = ", ".join(m.value for m in FloorMaterial)
        raise FieldError(f"{where}.material: expected one of {known}, got {material!r}") from None
    lo = _numbers(_require(t, "min", where), 2, f"{where}.min")
    hi = _numbers(_require(t, "max", where), 2, f"{where}.max")
    _ordered(lo, hi, where)
    return FloorPatch(name=name, material=mat, min_ne=(lo[0], lo[1]), max_ne=(hi[0], hi[1]))


def _parse_source(data: object, where: str) -> RadiationSource:
    t = table(data, where, {"name", "position", "strength_cps"})
    name = _name(t, where)
    pos = _numbers(_require(t, "position", where), 3, f"{where}.position")
    strength = _require(t, "strength_cps", where)
    if isinstance(strength, bool) or not isinstance(strength, int | float) or not strength > 0:
        raise FieldError(f"{where}.strength_cps: expected a number > 0, got {strength!r}")
    return RadiationSource(name=name, pos_n=_up_to_ned(pos), strength_cps=float(strength))


def _parse_origin(data: object) -> GeoOrigin:
    t = table(data, "origin", {"lat_deg", "lon_deg", "alt_amsl_m"})
    return GeoOrigin(**{k: number(v, f"origin.{k}") for k, v in t.items()})


def _inside_room(p: Vec3, room: tuple[Vec3, Vec3]) -> bool:
    rmin, rmax = room
    return all(rmin[i] <= p[i] <= rmax[i] for i in range(3))


def _over_box(x: float, y: float, b: Box) -> bool:
    return b.min_n[0] <= x <= b.max_n[0] and b.min_n[1] <= y <= b.max_n[1]


def _inside_box(p: Vec3, b: Box) -> bool:
    return all(b.min_n[i] < p[i] < b.max_n[i] for i in range(3))


def _parse_starts(raw: object, room: tuple[Vec3, Vec3], boxes: tuple[Box, ...]) -> list[Vec3]:
    if not isinstance(raw, list) or not raw:
        raise FieldError("start_positions: expected a non-empty array of [x, y] or [x, y, z_up]")
    starts: list[Vec3] = []
    for i, s in enumerate(raw):
        where = f"start_positions[{i}]"
        size = len(s) if isinstance(s, list) else -1
        if size not in (2, 3):
            got = f"{size} numbers" if size >= 0 else type(s).__name__
            raise FieldError(f"{where}: expected [x, y] or [x, y, z_up], got {got}")
        p = _numbers(s, size, where)
        if len(p) == 3:
            pos = _up_to_ned(p)
        else:  # on top of whatever stands there, else on the floor
            tops = [b.min_n[2] for b in boxes if _over_box(p[0], p[1], b)]
            pos = (p[0], p[1], min(tops, default=room[1][2]))
        if not _inside_room(pos, room):
            raise FieldError(f"{where}: outside the room")
        for b in boxes:
            if _inside_box(pos, b):
                raise FieldError(f"{where}: inside box {b.name!r}")
        starts.append(pos)
    return starts


def parse_world(data: Mapping[str, Any], *, default_name: str = "world") -> WorldSpec:
    """A WorldSpec from a parsed world file (FieldError naming the field)."""
    data = table(data, "world", _TOP_KEYS)
    name = data.get("name", default_name)
    if not isinstance(name, str) or not name.strip():
        raise FieldError(f"name: expected a non-empty string, got {name!r}")

    room_t = table(_require(data, "room", "world"), "room", {"min", "max"})
    lo = _numbers(_require(room_t, "min", "room"), 3, "room.min")
    hi = _numbers(_require(room_t, "max", "room"), 3, "room.max")
    _ordered(lo, hi, "room")
    room = ((lo[0], lo[1], 0.0 - hi[2]), (hi[0], hi[1], 0.0 - lo[2]))

    def _list(key: str) -> list[Any]:
        value = data.get(key, [])
        if not isinstance(value, list):
            raise FieldError(f"{key}: expected an array of tables ([[{key}]])")
        return value

    boxes = tuple(_parse_box(b, f"boxes[{i}]", room) for i, b in enumerate(_list("boxes")))
    names = [b.name for b in boxes]
    for i, n in enumerate(names):
        if n in names[:i]:
            raise FieldError(f"boxes[{i}].name: duplicate box name {n!r}")
    carpets = tuple(_parse_patch(p, f"floor[{i}]") for i, p in enumerate(_list("floor")))
    sources = tuple(_parse_source(s, f"sources[{i}]") for i, s in enumerate(_list("sources")))

    strongest = max((s.strength_cps for s in sources), default=0.0)
    rad_t = table(data.get("radiation", {}), "radiation", {"background_cps"})
    background = rad_t.get("background_cps", 0.01 * strongest)
    if isinstance(background, bool) or not isinstance(background, int | float) or background < 0:
        raise FieldError(f"radiation.background_cps: expected a number >= 0, got {background!r}")

    mocap_t = table(data.get("mocap", {}), "mocap", {"enabled"})
    mocap_enabled = mocap_t.get("enabled", True)
    if not isinstance(mocap_enabled, bool):
        raise FieldError(f"mocap.enabled: expected true or false, got {mocap_enabled!r}")

    starts = _parse_starts(data.get("start_positions", [[0.0, 0.0]]), room, boxes)
    return WorldSpec(
        name=name,
        room_min_n=room[0],
        room_max_n=room[1],
        boxes=boxes,
        carpets=carpets,
        sources=sources,
        background_cps=float(background),
        mocap_enabled=mocap_enabled,
        start_positions_n=tuple(starts),
        origin=_parse_origin(data.get("origin", {})),
        simulator={k: data[k] for k in SIMULATOR_TABLES if k in data},
    )


def load_world_file(path: Path) -> WorldSpec:
    """Read and validate a world file; any problem raises WorldFileError (one line)."""
    data = read_toml(path, noun="world file", error=WorldFileError)
    try:
        return parse_world(data, default_name=path.stem)
    except FieldError as exc:
        raise WorldFileError(f"{path}: {exc}") from None
