"""Mission files: TOML under `missions/`, loaded into a typed, validated `MissionSpec`.

A bad file ends in one line naming the file, the field, its line when it can be found, what
was wrong and what is expected, e.g.
`missions/x.toml:12: planner.kind: expected one of epbha, flocking, radiation, got "epbh"`.

Positions in mission files are written as a user thinks of a room: `[x, y, alt]` with x north,
y east and altitude positive up (metres); they are turned into local NED here, once.

    name = "epbha_table"
    world = "../worlds/table_room.toml"    # relative to the mission file
    [[vehicles]]  sysid = 1, start = [x, y, alt]   (start: kinematic runs only; default the
                                                    world's start points)
    [flight]      takeoff_alt_m, land, max_duration_s, profile ("apm25" | "copter4"),
                  speedup (SITL and station clock), position_tolerance_m, settle_s,
                  step_timeout_s (when a planner's set position counts as reached),
                  arm_timeout_s (each vehicle's arm asked again until then; default 30)
    [planner]     kind = "epbha" | "flocking" | "radiation", then the planner's parameters by
                  their field names, plus max_steps, seed, noise_sigma_m, max_samples,
                  floor_margin_m (see gcs.mission.planner_params)
    [goal]        position = [x, y, alt], individual = [[x, y, alt], ...], tolerance_m
    [station]     the vehicles' station configuration over its defaults, as a station TOML
                  (`fly --config`) writes it, e.g. [station.position.gains_xy]
"""

from __future__ import annotations

import enum
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gcs.config import StationConfig, config_from_table
from gcs.errors import UsageError
from gcs.launch import ARM_TIMEOUT_S
from worldfile import parse_toml

Vec3 = tuple[float, float, float]


class PlannerKind(enum.Enum):
    """Which of the thesis's planners a mission flies."""

    EPBHA = "epbha"
    FLOCKING = "flocking"
    RADIATION = "radiation"


@dataclass(frozen=True, slots=True)
class VehicleSpec:
    """One vehicle of the mission: its system id and where it starts (NED, on the floor)."""

    sysid: int
    start_n: Vec3 | None = None


@dataclass(frozen=True, slots=True)
class MissionSpec:
    """A validated mission file."""

    path: Path
    name: str
    world_path: Path | None
    vehicles: tuple[VehicleSpec, ...]
    takeoff_alt_m: float
    planner: PlannerKind
    planner_params: dict[str, Any]
    goals_n: tuple[Vec3, ...]
    goal_tolerance_m: float
    land: bool
    max_duration_s: float
    profile: str
    text: str = field(repr=False, default="")
    speedup: float = 1.0  # bundled SITL and station clock, times real time
    position_tolerance_m: float = 0.08  # a set position is reached within this (mocap, 3-D)
    settle_s: float = 0.4  # ... for this long (station clock)
    step_timeout_s: float = 8.0  # a set position not reached by then counts as reached anyway
    station: StationConfig | None = None  # None: the station's defaults (or `--config`'s)
    arm_timeout_s: float = ARM_TIMEOUT_S  # arms asked again until this after the request

    @property
    def goal_n(self) -> Vec3 | None:
        """The first (common) goal, if any."""
        return self.goals_n[0] if self.goals_n else None


class _Reader:
    """Walks a parsed TOML table and reports errors with the field's dotted name and line."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.lines = text.splitlines()

    def fail(self, dotted: str, problem: str) -> UsageError:
        line = self._line_of(dotted)
        where = f"{self.path}:{line}" if line else str(self.path)
        return UsageError(f"{where}: {dotted}: {problem}")

    def _line_of(self, dotted: str) -> int | None:
        parts = re.sub(r"\[\d+\]", "", dotted).split(".")
        key = parts[-1]
        table = ".".join(parts[:-1])
        in_table = table == ""
        for number, raw in enumerate(self.lines, start=1):
            line = raw.strip()
            header = re.match(r"^\[\[?([^\]]+)\]\]?$", line)
            if header:
                name = header.group(1).strip()
                if name == ".".join(parts):
                    return number
                in_table = name == table
                continue
            if in_table and re.match(rf"^{re.escape(key)}\s*=", line):
                return number
        return None

    def number(self, table: dict[str, Any], key: str, dotted: str, default: float | None = None,
               *, positive: bool = False) -> float:
        value = table.get(key, default)
        if value is None:
            raise self.fail(dotted, "missing; expected a number")
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(dotted, f"expected a number, got {value!r}")
        if positive and value <= 0:
            raise self.fail(dotted, f"expected a positive number, got {value!r}")
        return float(value)

    def vec3(self, value: Any, dotted: str) -> Vec3:
        if (
            not isinstance(value, list)
            or len(value) != 3
            or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
        ):
            raise self.fail(dotted, f"expected [x, y, alt] (3 numbers, metres), got {value!r}")
        x, y, alt = (float(v) for v in value)
        return (x, y, -alt)


PLANNER_KEYS = {"kind"}


def load_mission(path: str | Path) -> MissionSpec:
    """Read and validate a mission file; raise UsageError with one line on any problem."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise UsageError(f"{path}: no such mission file") from None
    except OSError as exc:
        raise UsageError(f"{path}: cannot read mission file ({exc.strerror or exc})") from None
    data = parse_toml(raw, label=str(path), noun="mission file", error=UsageError)
    text = raw.decode("utf-8")
    r = _Reader(path, text)

    name = data.get("name", path.stem)
    if not isinstance(name, str):
        raise r.fail("name", f"expected a string, got {name!r}")

    world_path: Path | None = None
    if "world" in data:
        world = data["world"]
        if not isinstance(world, str):
            raise r.fail("world", f"expected a path to a world file, got {world!r}")
        world_path = (path.parent / world).resolve()
        if not world_path.is_file():
            raise r.fail("world", f"world file {world_path} does not exist")

    vehicles = _vehicles(r, data)

    flight = data.get("flight", {})
    if not isinstance(flight, dict):
        raise r.fail("flight", "expected a table")
    takeoff_alt_m = r.number(flight, "takeoff_alt_m", "flight.takeoff_alt_m", 1.0, positive=True)
    land = flight.get("land", True)
    if not isinstance(land, bool):
        raise r.fail("flight.land", f"expected true or false, got {land!r}")
    max_duration_s = r.number(flight, "max_duration_s", "flight.max_duration_s", 600.0,
                              positive=True)
    profile = flight.get("profile", "apm25")
    if profile not in ("apm25", "copter4"):
        raise r.fail("flight.profile", f"expected apm25 or copter4, got {profile!r}")

    speedup = r.number(flight, "speedup", "flight.speedup", 1.0, positive=True)
    if speedup > 50:
        raise r.fail("flight.speedup", f"expected 0 < speedup <= 50, got {speedup!r}")
    position_tolerance_m = r.number(flight, "position_tolerance_m", "flight.position_tolerance_m",
                                    0.08, positive=True)
    settle_s = r.number(flight, "settle_s", "flight.settle_s", 0.4, positive=True)
    step_timeout_s = r.number(flight, "step_timeout_s", "flight.step_timeout_s", 8.0,
                              positive=True)
    arm_timeout_s = r.number(flight, "arm_timeout_s", "flight.arm_timeout_s", ARM_TIMEOUT_S,
                             positive=True)

    planner_table = data.get("planner")
    if not isinstance(planner_table, dict):
        raise r.fail("planner", "missing; expected a [planner] table with kind = ...")
    kind_name = planner_table.get("kind")
    kinds = ", ".join(k.value for k in PlannerKind)
    try:
        planner = PlannerKind(kind_name)
    except ValueError:
        raise r.fail("planner.kind", f"expected one of {kinds}, got {kind_name!r}") from None
    params = {k: v for k, v in planner_table.items() if k not in PLANNER_KEYS}

    goals_n, tolerance_m = _goals(r, data, planner)

    station: StationConfig | None = None
    if "station" in data:
        if not isinstance(data["station"], dict):
            raise r.fail("station", "expected a table of station settings")
        station = config_from_table(data["station"], f"{path}: station.")

    return MissionSpec(
        path=path,
        name=name,
        world_path=world_path,
        vehicles=vehicles,
        takeoff_alt_m=takeoff_alt_m,
        planner=planner,
        planner_params=params,
        goals_n=goals_n,
        goal_tolerance_m=tolerance_m,
        land=land,
        max_duration_s=max_duration_s,
        profile=profile,
        text=text,
        speedup=speedup,
        position_tolerance_m=position_tolerance_m,
        settle_s=settle_s,
        step_timeout_s=step_timeout_s,
        station=station,
        arm_timeout_s=arm_timeout_s,
    )


def _vehicles(r: _Reader, data: dict[str, Any]) -> tuple[VehicleSpec, ...]:
    raw = data.get("vehicles", [{"sysid": 1}])
    if not isinstance(raw, list) or not raw:
        raise r.fail("vehicles", "expected one or more [[vehicles]] tables")
    out: list[VehicleSpec] = []
    seen: set[int] = set()
    for i, v in enumerate(raw):
        dotted = f"vehicles[{i}]"
        if not isinstance(v, dict):
            raise r.fail(dotted, "expected a table")
        sysid = v.get("sysid", i + 1)
        if isinstance(sysid, bool) or not isinstance(sysid, int) or not 1 <= sysid <= 250:
            raise r.fail(f"{dotted}.sysid", f"expected a system id 1..250, got {sysid!r}")
        if sysid in seen:
            raise r.fail(f"{dotted}.sysid", f"system id {sysid} used twice")
        seen.add(sysid)
        start = r.vec3(v["start"], f"{dotted}.start") if "start" in v else None
        out.append(VehicleSpec(sysid=sysid, start_n=start))
    return tuple(out)


def _goals(r: _Reader, data: dict[str, Any], planner: PlannerKind) -> tuple[tuple[Vec3, ...],
                                                                             float]:
    goal = data.get("goal", {})
    if not isinstance(goal, dict):
        raise r.fail("goal", "expected a [goal] table")
    tolerance_m = r.number(goal, "tolerance_m", "goal.tolerance_m", 0.25, positive=True)
    goals: list[Vec3] = []
    if "position" in goal:
        goals.append(r.vec3(goal["position"], "goal.position"))
    extra = goal.get("individual", [])
    if not isinstance(extra, list):
        raise r.fail("goal.individual", "expected a list of [x, y, alt] positions")
    goals.extend(r.vec3(g, f"goal.individual[{i}]") for i, g in enumerate(extra))
    if planner in (PlannerKind.EPBHA, PlannerKind.FLOCKING) and not goals:
        raise r.fail("goal.position", f"missing; a {planner.value} mission needs a goal")
    return tuple(goals), tolerance_m
