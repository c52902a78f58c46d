"""Worlds the simulated vehicles fly in: room, boxes, floor materials, radiation, start points.

World files are TOML. Coordinates in the FILE are "x north, y east, z up" in metres with z = 0
on the floor, because heights are what people measure; the loader converts them to local NED
(z down) for everything in code. Top-level keys:

    name = "table_room"
    [room]       min = [x, y, z_up], max = [x, y, z_up]      # the room's inside extents
    [[boxes]]    name = "...", min = [x, y, z_up], max = [x, y, z_up]
    [[floor]]    name = "...", material = "carpet", min = [x, y], max = [x, y]
    [[sources]]  name = "...", position = [x, y, z_up], strength_cps = 5000.0  # counts/s at 1 m
    [radiation]  background_cps = 50.0    # default: 1 % of the strongest source
    [mocap]      enabled = true
    start_positions = [[x, y], [x, y, z_up], ...]   # no z_up: on top of what stands there
    [origin]     lat_deg = ..., lon_deg = ..., alt_amsl_m = ...
    [sensors.imu] / [sensors.sonar] / ... overrides (see sitl.sensor_params)
    [vehicle]    overrides of sitl.params.VehicleParams
    [autopilot]  realistic_boot = true      # copter4: the real ≈ 24 s pre-arm delay
                 copter4_version = "4.6"    # parameter names of a 4.x before 4.7
    [autopilot.params]  FS_BATT_ENABLE = 1   # values the vehicle boots with (the profile's names)

A bad file raises WorldError with one line: `<file>: <field>: <problem>`.
"""

from __future__ import annotations

import enum
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sitl.autopilot.profile import AutopilotOptions
from sitl.params import ParamError, VehicleParams, build_dataclass
from sitl.sensor_params import SensorParams

Vec3 = tuple[float, float, float]
Vec2 = tuple[float, float]


class WorldError(ValueError):
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
class World:
    """A room and what is in it, all in local NED metres."""

    name: str = "empty_room"
    room_min_n: Vec3 = (-3.0, -3.0, -3.0)  # z: the ceiling
    room_max_n: Vec3 = (3.0, 3.0, 0.0)  # z: the floor
    boxes: tuple[Box, ...] = ()
    carpets: tuple[FloorPatch, ...] = ()
    sources: tuple[RadiationSource, ...] = ()
    background_cps: float = 0.0
    mocap_enabled: bool = True
    start_positions_n: tuple[Vec3, ...] = ((0.0, 0.0, 0.0),)
    origin: GeoOrigin = field(default_factory=GeoOrigin)
    sensors: SensorParams = field(default_factory=SensorParams)
    vehicle: VehicleParams = field(default_factory=VehicleParams)
    autopilot: AutopilotOptions = field(default_factory=AutopilotOptions)

    @property
    def floor_z_n(self) -> float:
        """NED z of the floor."""
        return self.room_max_n[2]

    def floor_material(self, north_m: float, east_m: float) -> FloorMaterial:
        """Material of the floor at (north, east): the last listed patch that covers it wins."""
        for patch in reversed(self.carpets):
            if patch.contains(north_m, east_m):
                return patch.material
        return FloorMaterial.HARD

    def box(self, name: str) -> Box:
        """The box called `name` (KeyError if none)."""
        for b in self.boxes:
            if b.name == name:
                return b
        raise KeyError(name)


def default_world() -> World:
    """A 6 x 6 x 3 m empty room, hard floor, motion capture on, start at the centre."""
    return World()


_TOP_KEYS = {
    "name",
    "room",
    "boxes",
    "floor",
    "sources",
    "radiation",
    "mocap",
    "start_positions",
    "origin",
    "sensors",
    "vehicle",
    "autopilot",
}


def _table(data: Any, where: str, allowed: set[str]) -> Mapping[str, Any]:
    if not isinstance(data, Mapping):
        raise ParamError(f"{where}: expected a table, got {type(data).__name__}")
    for key in data:
        if key not in allowed:
            raise ParamError(f"{where}.{key}: unknown field (known: {', '.join(sorted(allowed))})")
    return data


def _require(data: Mapping[str, Any], key: str, where: str) -> Any:
    if key not in data:
        raise ParamError(f"{where}.{key}: missing")
    return data[key]


def _numbers(value: Any, n: int, where: str) -> tuple[float, ...]:
    if not isinstance(value, list | tuple):
        raise ParamError(f"{where}: expected {n} numbers, got {type(value).__name__}")
    if len(value) != n:
        raise ParamError(f"{where}: expected {n} numbers, got {len(value)}")
    return tuple(_number(v, f"{where}[{i}]") for i, v in enumerate(value))


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ParamError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _name(data: Mapping[str, Any], where: str) -> str:
    name = _require(data, "name", where)
    if not isinstance(name, str) or not name.strip():
        raise ParamError(f"{where}.name: expected a non-empty string, got {name!r}")
    return name


def _up_to_ned(p: tuple[float, ...]) -> Vec3:
    return (p[0], p[1], 0.0 - p[2])


def _ordered(lo: tuple[float, ...], hi: tuple[float, ...], where: str) -> None:
    for i, (a, b) in enumerate(zip(lo, hi, strict=True)):
        if not a < b:
            raise ParamError(f"{where}.max[{i}]: must be greater than min[{i}] ({a}), got {b}")


def _parse_box(data: Any, where: str, room: tuple[Vec3, Vec3]) -> Box:
    data = _table(data, where, {"name", "min", "max"})
    name = _name(data, where)
    lo = _numbers(_require(data, "min", where), 3, f"{where}.min")
    hi = _numbers(_require(data, "max", where), 3, f"{where}.max")
    _ordered(lo, hi, where)
    min_n = (lo[0], lo[1], 0.0 - hi[2])
    max_n = (hi[0], hi[1], 0.0 - lo[2])
    rmin, rmax = room
    for i in range(3):
        if max_n[i] <= rmin[i] or min_n[i] >= rmax[i]:
            raise ParamError(f"{where}: lies entirely outside the room")
    return Box(name=name, min_n=min_n, max_n=max_n)


def _parse_patch(data: Any, where: str) -> FloorPatch:
    data = _table(data, where, {"name", "material", "min", "max"})
    name = _name(data, where)
    material = _require(data, "material", where)
    try:
        mat = FloorMaterial(material)
    except ValueError:
        known = ", ".join(m.value for m in FloorMaterial)
        raise ParamError(f"{where}.material: expected one of {known}, got {material!r}") from None
    lo = _numbers(_require(data, "min", where), 2, f"{where}.min")
    hi = _numbers(_require(data, "max", where), 2, f"{where}.max")
    _ordered(lo, hi, where)
    return FloorPatch(name=name, material=mat, min_ne=(lo[0], lo[1]), max_ne=(hi[0], hi[1]))


def _parse_source(data: Any, where: str) -> RadiationSource:
    data = _table(data, where, {"name", "position", "strength_cps"})
    name = _name(data, where)
    pos = _numbers(_require(data, "position", where), 3, f"{where}.position")
    strength = _require(data, "strength_cps", where)
    if isinstance(strength, bool) or not isinstance(strength, int | float) or not strength > 0:
        raise ParamError(f"{where}.strength_cps: expected a number > 0, got {strength!r}")
    return RadiationSource(name=name, pos_n=_up_to_ned(pos), strength_cps=float(strength))


def _inside_room(p: Vec3, room: tuple[Vec3, Vec3]) -> bool:
    rmin, rmax = room
    return all(rmin[i] <= p[i] <= rmax[i] for i in range(3))


def _over_box(x: float, y: float, b: Box) -> bool:
    return b.min_n[0] <= x <= b.max_n[0] and b.min_n[1] <= y <= b.max_n[1]


def _inside_box(p: Vec3, b: Box) -> bool:
    return all(b.min_n[i] < p[i] < b.max_n[i] for i in range(3))


def world_from_toml(data: Mapping[str, Any]) -> World:
    """Build a World from parsed TOML (raises ParamError naming the field)."""
    data = _table(data, "world", _TOP_KEYS)
    name = data.get("name", "world")
    if not isinstance(name, str) or not name.strip():
        raise ParamError(f"name: expected a non-empty string, got {name!r}")

    room_t = _table(_require(data, "room", "world"), "room", {"min", "max"})
    lo = _numbers(_require(room_t, "min", "room"), 3, "room.min")
    hi = _numbers(_require(room_t, "max", "room"), 3, "room.max")
    _ordered(lo, hi, "room")
    room = ((lo[0], lo[1], 0.0 - hi[2]), (hi[0], hi[1], 0.0 - lo[2]))

    def _list(key: str) -> list[Any]:
        value = data.get(key, [])
        if not isinstance(value, list):
            raise ParamError(f"{key}: expected an array of tables ([[{key}]])")
        return value

    boxes = tuple(_parse_box(b, f"boxes[{i}]", room) for i, b in enumerate(_list("boxes")))
    names = [b.name for b in boxes]
    for i, n in enumerate(names):
        if n in names[:i]:
            raise ParamError(f"boxes[{i}].name: duplicate box name {n!r}")
    carpets = tuple(_parse_patch(p, f"floor[{i}]") for i, p in enumerate(_list("floor")))
    sources = tuple(_parse_source(s, f"sources[{i}]") for i, s in enumerate(_list("sources")))

    strongest = max((s.strength_cps for s in sources), default=0.0)
    rad_t = _table(data.get("radiation", {}), "radiation", {"background_cps"})
    background = rad_t.get("background_cps", 0.01 * strongest)
    if isinstance(background, bool) or not isinstance(background, int | float) or background < 0:
        raise ParamError(f"radiation.background_cps: expected a number >= 0, got {background!r}")

    mocap_t = _table(data.get("mocap", {}), "mocap", {"enabled"})
    mocap_enabled = mocap_t.get("enabled", True)
    if not isinstance(mocap_enabled, bool):
        raise ParamError(f"mocap.enabled: expected true or false, got {mocap_enabled!r}")

    starts_raw = data.get("start_positions", [[0.0, 0.0]])
    if not isinstance(starts_raw, list) or not starts_raw:
        raise ParamError("start_positions: expected a non-empty array of [x, y] or [x, y, z_up]")
    starts: list[Vec3] = []
    for i, s in enumerate(starts_raw):
        where = f"start_positions[{i}]"
        size = len(s) if isinstance(s, list) else -1
        if size not in (2, 3):
            got = f"{size} numbers" if size >= 0 else type(s).__name__
            raise ParamError(f"{where}: expected [x, y] or [x, y, z_up], got {got}")
        p = _numbers(s, size, where)
        if len(p) == 3:
            pos = _up_to_ned(p)
        else:  # on top of whatever stands there, else on the floor
            tops = [b.min_n[2] for b in boxes if _over_box(p[0], p[1], b)]
            pos = (p[0], p[1], min(tops, default=room[1][2]))
        if not _inside_room(pos, room):
            raise ParamError(f"{where}: outside the room")
        for b in boxes:
            if _inside_box(pos, b):
                raise ParamError(f"{where}: inside box {b.name!r}")
        starts.append(pos)

    origin = build_dataclass(GeoOrigin, data.get("origin", {}), "origin")
    sensors = SensorParams.from_toml(data.get("sensors", {}))
    vehicle = build_dataclass(VehicleParams, data.get("vehicle", {}), "vehicle")
    autopilot = _parse_autopilot(data.get("autopilot", {}))
    return World(
        name=name,
        room_min_n=room[0],
        room_max_n=room[1],
        boxes=boxes,
        carpets=carpets,
        sources=sources,
        background_cps=float(background),
        mocap_enabled=mocap_enabled,
        start_positions_n=tuple(starts),
        origin=origin,
        sensors=sensors,
        vehicle=vehicle,
        autopilot=autopilot,
    )


def _parse_autopilot(data: Any) -> AutopilotOptions:
    data = _table(data, "autopilot", {"realistic_boot", "copter4_version", "params"})
    realistic = data.get("realistic_boot", False)
    if not isinstance(realistic, bool):
        raise ParamError(f"autopilot.realistic_boot: expected true or false, got {realistic!r}")
    version = data.get("copter4_version", "4.7")
    values = data.get("params", {})
    if not isinstance(values, Mapping):
        raise ParamError(f"autopilot.params: expected a table, got {type(values).__name__}")
    params = [(str(k), _number(v, f"autopilot.params.{k}")) for k, v in values.items()]
    try:
        return AutopilotOptions(realistic_boot=realistic, copter4_version=str(version),
                                params=tuple(params))
    except ValueError as exc:
        raise ParamError(f"autopilot.{exc}") from None


def load_world(path: str | Path) -> World:
    """Read and validate a world TOML file; any problem raises WorldError (one line)."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise WorldError(f"{p}: no such world file") from None
    except OSError as exc:
        raise WorldError(f"{p}: cannot read ({exc.strerror or exc})") from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise WorldError(f"{p}: not UTF-8 text") from None
    except tomllib.TOMLDecodeError as exc:
        raise WorldError(f"{p}: invalid TOML ({exc})") from None
    try:
        return world_from_toml(data)
    except ParamError as exc:
        raise WorldError(f"{p}: {exc}") from None
