"""Worlds the simulated vehicles fly in: the world file (`worldfile`) plus the simulator's tables.

The room, boxes, floor patches, radiation sources, start points and origin are read by the
neutral `worldfile` package, which the station reads too; this adds what only the simulator
knows: `[sensors.*]` (see sitl.sensor_params), `[vehicle]` (sitl.params.VehicleParams) and

    [autopilot]  realistic_boot = true      # copter4: the real ≈ 24 s pre-arm delay
                 copter4_version = "4.6"    # parameter names of a 4.x before 4.7
                 rc_input = "absent"        # the receiver: "min" (default), "mid", "absent"
                 gps = true                 # a GPS fix with home (default none, as indoors)
                 home_distance_m = 3.0      # how far the GPS puts the vehicle from home
    [autopilot.params]  FS_BATT_ENABLE = 1   # values the vehicle boots with (the profile's names)

A bad file raises WorldError with one line: `<file>: <field>: <problem>`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sitl.autopilot.profile import AutopilotOptions, RcInput
from sitl.params import ParamError, VehicleParams, build_dataclass
from sitl.sensor_params import SensorParams
from worldfile import (
    Box,
    FieldError,
    FloorMaterial,
    FloorPatch,
    GeoOrigin,
    RadiationSource,
    Vec2,
    Vec3,
    WorldFileError,
    WorldSpec,
    parse_world,
    read_toml,
)
from worldfile.schema import number, table

__all__ = [
    "Box",
    "FloorMaterial",
    "FloorPatch",
    "GeoOrigin",
    "RadiationSource",
    "Vec2",
    "Vec3",
    "World",
    "WorldError",
    "default_world",
    "load_world",
    "world_from_toml",
]


class WorldError(WorldFileError):
    """A world file is missing, unreadable or invalid; the message is one line."""


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


def world_from_toml(data: Mapping[str, Any], *, default_name: str = "world") -> World:
    """Build a World from parsed TOML (raises ParamError naming the field)."""
    try:
        spec = parse_world(data, default_name=default_name)
    except FieldError as exc:
        raise ParamError(str(exc)) from None
    return world_from_spec(spec)


def world_from_spec(spec: WorldSpec) -> World:
    """The simulator's World: the file's geometry and its own tables (ParamError naming the
    field)."""
    sim = spec.simulator
    return World(
        name=spec.name,
        room_min_n=spec.room_min_n,
        room_max_n=spec.room_max_n,
        boxes=spec.boxes,
        carpets=spec.carpets,
        sources=spec.sources,
        background_cps=spec.background_cps,
        mocap_enabled=spec.mocap_enabled,
        start_positions_n=spec.start_positions_n,
        origin=spec.origin,
        sensors=SensorParams.from_toml(sim.get("sensors", {})),
        vehicle=build_dataclass(VehicleParams, sim.get("vehicle", {}), "vehicle"),
        autopilot=_parse_autopilot(sim.get("autopilot", {})),
    )


def _parse_autopilot(data: Any) -> AutopilotOptions:
    try:
        data = table(data, "autopilot", {"realistic_boot", "copter4_version", "params",
                                         "rc_input", "gps", "home_distance_m"})
    except FieldError as exc:
        raise ParamError(str(exc)) from None
    defaults = AutopilotOptions()
    flags: dict[str, bool] = {}
    for key in ("realistic_boot", "gps"):
        flag = data.get(key, getattr(defaults, key))
        if not isinstance(flag, bool):
            raise ParamError(f"autopilot.{key}: expected true or false, got {flag!r}")
        flags[key] = flag
    receivers = [r.value for r in RcInput]
    rc_input = data.get("rc_input", defaults.rc_input.value)
    if rc_input not in receivers:
        raise ParamError(f"autopilot.rc_input: expected one of {', '.join(receivers)}, "
                         f"got {rc_input!r}")
    version = data.get("copter4_version", "4.7")
    values = data.get("params", {})
    if not isinstance(values, Mapping):
        raise ParamError(f"autopilot.params: expected a table, got {type(values).__name__}")
    try:
        params = [(str(k), number(v, f"autopilot.params.{k}")) for k, v in values.items()]
        home_m = number(data.get("home_distance_m", defaults.home_distance_m),
                        "autopilot.home_distance_m")
    except FieldError as exc:
        raise ParamError(str(exc)) from None
    try:
        return AutopilotOptions(realistic_boot=flags["realistic_boot"],
                                copter4_version=str(version), params=tuple(params),
                                rc_input=RcInput(rc_input), gps=flags["gps"],
                                home_distance_m=home_m)
    except ValueError as exc:
        raise ParamError(f"autopilot.{exc}") from None


def load_world(path: str | Path) -> World:
    """Read and validate a world TOML file; any problem raises WorldError (one line)."""
    p = Path(path)
    data = read_toml(p, noun="world file", error=WorldError)
    try:
        return world_from_toml(data, default_name=p.stem)
    except ParamError as exc:
        raise WorldError(f"{p}: {exc}") from None
