"""Campaign files: what every run flies, the axes that vary between runs, and how runs are chosen.

    name = "hold_gains"              # default: the file's stem
    kind = "grid"                    # grid (every combination), random (samples), search
    samples = 20                     # random: how many runs
    sample_seed = 0                  # random and search: the sampler's seed

    [fly]                            # each run: `quadgcs fly --lockstep` with these
    alt_m = 1.0
    hold_s = 30.0
    step_m = 0.0
    profile = "apm25"
    world = "../worlds/empty_room.toml"   # paths relative to this file
    config = "station.toml"               # a station TOML to start from
    record = false                        # an MCAP per run, in the output's flights/
    fix_failsafe = false                  # fly's --fix-failsafe (copter4 needs it)

    [axes]                           # grid: lists; random: lists or {min, max[, log]}
    seed = { range = [1, 50] }       # integers, both ends included
    "station.altitude.gains.kp" = [3.0, 4.0]     # any key of a station TOML
    "world.sensors.sonar.noise_m" = [0.01, 0.02] # any key of a world TOML
    world = ["../worlds/empty_room.toml", "../worlds/carpet_room.toml"]
    profile = ["apm25", "copter4"]
    "fly.alt_m" = [0.5, 1.0]         # any key of [fly] that is a number
    "link.fade" = ["none", "down", "up", "both"]  # a radio fade of the vehicle link, and its
    "link.fade_start_s" = [30.0]     # start and length in simulated s (holding from ~15 s);
    "link.fade_s" = [15.0]           # "link.loss" = [0.0, 0.05]: each frame lost, both ways

    [search]                         # kind = "search": Optuna TPE over the axes
    trials = 30
    seeds = [1, 2, 3]                # every trial flies each seed (and each world)
    worlds = ["../worlds/empty_room.toml", "../worlds/carpet_room.toml"]
    objective = "rms_error_m"        # a run metric, minimised: its mean over a trial's runs
    failed_penalty = 1.0             # added to the objective per failed run

A mission campaign names a mission file instead of [fly]: each run is `quadgcs mission run
--lockstep` with one combination of its axes, the seed and any [planner] key of the mission:

    mission = "../missions/epbha_table.toml"
    [axes]
    seed = { range = [1, 50] }
    "planner.keep_off_vertical_m" = [0.15, 0.25]

Every problem is one line naming the file, the key and what was expected (`CampaignError`).
Values are checked here, before any run: a station key through the station's own TOML loader,
a world key through the SITL's (`check_world`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gcs.campaign.tables import check_faults, check_world, set_dotted, world_table
from gcs.config import config_from_table
from gcs.errors import UsageError
from gcs.flight import FlightPlan
from worldfile import read_toml

KINDS = ("grid", "random", "search")
TOP_KEYS = {"name", "kind", "samples", "sample_seed", "fly", "mission", "axes", "search"}
FLY_KEYS = {"alt_m": float, "hold_s": float, "step_m": float, "takeoff_delay_s": float,
            "profile": str, "world": str, "config": str, "record": bool,
            "fix_failsafe": bool}
PROFILES = ("apm25", "copter4")
SEARCH_KEYS = {"trials", "seeds", "worlds", "objective", "failed_penalty"}
NUMERIC_FLY = ("alt_m", "hold_s", "step_m", "takeoff_delay_s")
LINK_KEYS = ("loss", "fade", "fade_start_s", "fade_s")


class CampaignError(UsageError):
    """A campaign file that cannot be run (exit code 2)."""


@dataclass(frozen=True, slots=True)
class Range:
    """A random axis: uniform (or log-uniform) in [min, max]; integers if both ends are."""

    lo: float
    hi: float
    log: bool = False
    integer: bool = False


Axis = tuple[Any, ...] | Range


@dataclass(frozen=True, slots=True)
class BaseFlight:
    """What every run flies before the axes change it."""

    alt_m: float = 1.0
    hold_s: float = 30.0
    step_m: float = 0.0
    takeoff_delay_s: float = 0.0
    profile: str = "apm25"
    world: str | None = None  # paths as the file writes them, relative to `root`
    config: str | None = None
    record: bool = False
    fix_failsafe: bool = False  # fly's --fix-failsafe: copter4 ships FS_GCS_ENABLE 0, FS_OPTIONS 16
    root: Path = Path(".")  # the campaign file's directory

    def resolve(self, text: str | None) -> Path | None:
        """A path of the file (None stays None) from wherever the run happens."""
        return None if text is None else self.root / text

    @property
    def world_path(self) -> Path | None:
        """The base world file."""
        return self.resolve(self.world)

    @property
    def config_path(self) -> Path | None:
        """The base station file."""
        return self.resolve(self.config)


@dataclass(frozen=True, slots=True)
class BaseMission:
    """What every run of a mission campaign flies: the mission file, in lockstep."""

    mission: str  # as the file writes it, relative to `root`
    record: bool = False
    root: Path = Path(".")

    @property
    def mission_path(self) -> Path:
        """The mission file."""
        return self.root / self.mission


@dataclass(frozen=True, slots=True)
class SearchSpec:
    """kind = "search": trials, the runs of one trial and what they minimise."""

    trials: int = 20
    seeds: tuple[int, ...] = (1, 2, 3)
    worlds: tuple[str | None, ...] = (None,)  # as written, relative to the file
    objective: str = "rms_error_m"
    failed_penalty: float = 1.0


@dataclass(frozen=True, slots=True)
class Campaign:
    """A validated campaign file."""

    path: Path
    name: str
    kind: str
    base: BaseFlight | BaseMission
    axes: dict[str, Axis]
    samples: int = 0
    sample_seed: int = 0
    search: SearchSpec = field(default_factory=SearchSpec)


def _fail(path: Path, key: str, problem: str) -> CampaignError:
    return CampaignError(f"{path}: {key}: {problem}")


def _number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _rel(path: Path, key: str, text: Any, what: str) -> Path:
    if not isinstance(text, str) or not text:
        raise _fail(path, key, f"expected a path to a {what} file, got {text!r}")
    p = path.parent.resolve() / text
    if not p.is_file():
        raise _fail(path, key, f"no such {what} file {p}")
    return p


def load_campaign(path: str | Path) -> Campaign:
    """Read and check a campaign file; CampaignError (one line) for any problem."""
    p = Path(path)
    data = read_toml(p, label=str(p), noun="campaign file", error=CampaignError)
    for key in data:
        if key not in TOP_KEYS:
            raise _fail(p, key, f"unknown key; expected one of {sorted(TOP_KEYS)}")
    kind = data.get("kind", "grid")
    if kind not in KINDS:
        raise _fail(p, "kind", f"expected one of {list(KINDS)}, got {kind!r}")
    name = data.get("name", p.stem)
    if not isinstance(name, str) or not name or "/" in name:
        raise _fail(p, "name", f"expected a name without '/', got {name!r}")
    axes_raw = data.get("axes", {})
    if not isinstance(axes_raw, dict):
        raise _fail(p, "axes", "expected a table of axis = values")
    base: BaseFlight | BaseMission
    if "mission" in data:
        base = _mission_base(p, data, kind)
        axes = {k: _mission_axis(p, base, kind, k, v) for k, v in axes_raw.items()}
    else:
        base = _base(p, data.get("fly", {}))
        axes = {k: _axis(p, base, kind, k, v) for k, v in axes_raw.items()}
    samples = _int(p, data, "samples", None if kind == "random" else 1, 1)
    sample_seed = _int(p, data, "sample_seed", 0, 0)
    search = _search(p, data.get("search"), kind, axes)
    if kind == "grid" and not axes:
        raise _fail(p, "axes", "empty; expected at least one axis with values")
    if kind == "grid" and any(isinstance(a, Range) for a in axes.values()):
        bad = next(k for k, a in axes.items() if isinstance(a, Range))
        raise _fail(p, f"axes.{bad}", "a grid axis takes a list of values (or {range = [a, "
                    "b]}); {min, max} is for random and search")
    return Campaign(p, name, kind, base, axes, samples, sample_seed, search)


def _int(p: Path, data: dict[str, Any], key: str, default: int | None, lo: int) -> int:
    v = data.get(key, default)
    if v is None:
        raise _fail(p, key, f"missing; expected an integer >= {lo}")
    if isinstance(v, bool) or not isinstance(v, int) or v < lo:
        raise _fail(p, key, f"expected an integer >= {lo}, got {v!r}")
    return v


def _base(p: Path, fly: Any) -> BaseFlight:
    if not isinstance(fly, dict):
        raise _fail(p, "fly", "expected a table")
    kw: dict[str, Any] = {}
    for key, value in fly.items():
        kind = FLY_KEYS.get(key)
        where = f"fly.{key}"
        if kind is None:
            raise _fail(p, where, f"unknown key; expected one of {sorted(FLY_KEYS)}")
        if kind is float:
            if not _number(value):
                raise _fail(p, where, f"expected a number, got {value!r}")
            kw[key] = float(value)
        elif kind is bool:
            if not isinstance(value, bool):
                raise _fail(p, where, f"expected true or false, got {value!r}")
            kw[key] = value
        elif key == "profile":
            if value not in PROFILES:
                raise _fail(p, where, f"expected one of {list(PROFILES)}, got {value!r}")
            kw[key] = value
        else:
            _rel(p, where, value, "world" if key == "world" else "station config")
            kw[key] = value
    base = BaseFlight(**kw, root=p.parent.resolve())
    _check_plan(p, "fly", base, {})
    if base.config_path is not None:
        try:
            config_from_table(read_toml(base.config_path, label=str(base.config),
                                        noun="station config", error=UsageError))
        except UsageError as exc:
            raise _fail(p, "fly.config", str(exc)) from None
    _check_world(p, "fly.world", base.world_path, {})
    return base


def _mission_base(p: Path, data: dict[str, Any], kind: str) -> BaseMission:
    if "fly" in data:
        raise _fail(p, "fly", "a campaign flies a mission file or a [fly] table, not both")
    if kind == "search":
        raise _fail(p, "kind", "a search tunes [fly] flights; a mission campaign is a grid or "
                    "random")
    _rel(p, "mission", data["mission"], "mission")
    base = BaseMission(data["mission"], root=p.parent.resolve())
    _check_mission(p, "mission", base, {})
    return base


def _check_mission(p: Path, key: str, base: BaseMission, planner: dict[str, Any]) -> None:
    from gcs.campaign.mission_run import mission_with

    try:
        mission_with(base, planner)
    except UsageError as exc:
        raise _fail(p, key, f"{exc}") from None


def _samples(p: Path, key: str, raw: Any, kind: str) -> tuple[Axis, list[tuple[str, Any]]]:
    """An axis and the values to check of it, each with where it is in the file."""
    axis = _values(p, key, raw, kind)
    if isinstance(axis, Range):
        return axis, [(key, axis.lo), (key, axis.hi)]
    return axis, [(f"{key}[{i}]", v) for i, v in enumerate(axis)]


def _check_seed(p: Path, at: str, v: Any) -> None:
    if isinstance(v, bool) or not isinstance(v, int | float) or v != int(v) or v < 0:
        raise _fail(p, at, f"expected an integer >= 0, got {v!r}")


def _mission_axis(p: Path, base: BaseMission, kind: str, name: str, raw: Any) -> Axis:
    key = f"axes.{name}"
    axis, samples = _samples(p, key, raw, kind)
    for at, v in samples:
        if name == "seed":
            _check_seed(p, at, v)
        elif name.startswith("planner.") and name != "planner.kind":
            _check_mission(p, at, base, {name.removeprefix("planner."): v})
        else:
            raise _fail(p, key, "unknown axis; a mission campaign varies seed and planner.KEY "
                        "(a key of the mission's [planner] table)")
    return axis


def _check_plan(p: Path, key: str, base: BaseFlight, over: dict[str, float]) -> None:
    try:
        FlightPlan(alt_m=over.get("alt_m", base.alt_m), hold_s=over.get("hold_s", base.hold_s),
                   step_m=over.get("step_m", base.step_m),
                   takeoff_delay_s=over.get("takeoff_delay_s", base.takeoff_delay_s))
    except ValueError as exc:
        raise _fail(p, key, f"{exc}") from None


def _check_world(p: Path, key: str, world: Path | None, over: dict[str, Any]) -> None:
    try:
        check_world(world_table(world, over))
    except ValueError as exc:
        raise _fail(p, key, f"{exc}") from None


def _values(p: Path, key: str, raw: Any, kind: str) -> Axis:
    if isinstance(raw, dict):
        if set(raw) == {"range"}:
            r = raw["range"]
            if (not isinstance(r, list) or len(r) != 2
                    or not all(isinstance(x, int) and not isinstance(x, bool) for x in r)
                    or r[0] > r[1]):
                raise _fail(p, key, f"range: expected [first, last] integers, got {r!r}")
            return tuple(range(r[0], r[1] + 1))
        if kind == "grid" or not {"min", "max"} <= set(raw) <= {"min", "max", "log"}:
            raise _fail(p, key, "expected a list of values, {range = [first, last]} or (random, "
                        "search) {min = a, max = b, log = false}")
        lo, hi, log = raw["min"], raw["max"], raw.get("log", False)
        if not (_number(lo) and _number(hi) and lo < hi) or not isinstance(log, bool):
            raise _fail(p, key, f"expected numbers min < max, got {lo!r}, {hi!r}")
        if log and lo <= 0:
            raise _fail(p, key, "log: expected min > 0")
        both_int = isinstance(lo, int) and isinstance(hi, int)
        return Range(float(lo), float(hi), log, both_int)
    if not isinstance(raw, list):
        raise _fail(p, key, f"expected a list of values, got {raw!r}")
    if not raw:
        raise _fail(p, key, "empty list; expected at least one value")
    return tuple(raw)


def _axis(p: Path, base: BaseFlight, kind: str, name: str, raw: Any) -> Axis:
    key = f"axes.{name}"
    axis, samples = _samples(p, key, raw, kind)
    for at, v in samples:
        if name == "seed":
            _check_seed(p, at, v)
        elif name == "profile":
            if v not in PROFILES:
                raise _fail(p, at, f"expected one of {list(PROFILES)}, got {v!r}")
        elif name == "world":
            _check_world(p, at, _rel(p, at, v, "world"), {})
        elif name.startswith("fly."):
            field_name = name.removeprefix("fly.")
            if field_name not in NUMERIC_FLY:
                raise _fail(p, key, f"unknown axis; expected fly.{{{', '.join(NUMERIC_FLY)}}}")
            if not _number(v):
                raise _fail(p, at, f"expected a number, got {v!r}")
            _check_plan(p, at, base, {field_name: float(v)})
        elif name.startswith("station."):
            _check_station(p, at, name.removeprefix("station."), v)
        elif name.startswith("world."):
            _check_world(p, at, base.world_path, set_dotted({}, name.removeprefix("world."), v))
        elif name.startswith("link."):
            field_name = name.removeprefix("link.")
            if field_name not in LINK_KEYS:
                raise _fail(p, key, f"unknown axis; expected link.{{{', '.join(LINK_KEYS)}}}")
            try:
                check_faults({field_name: v})
            except (TypeError, ValueError) as exc:
                raise _fail(p, at, f"{exc}") from None
        else:
            raise _fail(p, key, "unknown axis; expected seed, profile, world, fly.KEY, "
                        "station.KEY (a station TOML key), world.KEY (a world TOML key) or "
                        "link.KEY (link faults)")
    return axis


def _check_station(p: Path, at: str, dotted: str, value: Any) -> None:
    try:
        config_from_table(set_dotted({}, dotted, value), "")
    except UsageError as exc:
        raise _fail(p, at, f"station {exc}") from None


def _search(p: Path, raw: Any, kind: str, axes: dict[str, Axis]) -> SearchSpec:
    if raw is None:
        if kind == "search":
            raise _fail(p, "search", "missing; kind = \"search\" needs a [search] table")
        return SearchSpec()
    if kind != "search":
        raise _fail(p, "search", f"only for kind = \"search\" (this file's kind is {kind!r})")
    if not isinstance(raw, dict):
        raise _fail(p, "search", "expected a table")
    for key in raw:
        if key not in SEARCH_KEYS:
            raise _fail(p, f"search.{key}", f"unknown key; expected one of {sorted(SEARCH_KEYS)}")
    trials = _int(p, raw, "trials", 20, 1)
    seeds = raw.get("seeds", [1, 2, 3])
    if (not isinstance(seeds, list) or not seeds
            or not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in seeds)):
        raise _fail(p, "search.seeds", f"expected a non-empty list of integers, got {seeds!r}")
    worlds_raw = raw.get("worlds")
    worlds: tuple[str | None, ...] = (None,)
    if worlds_raw is not None:
        if not isinstance(worlds_raw, list) or not worlds_raw:
            raise _fail(p, "search.worlds", "expected a non-empty list of world files")
        for i, w in enumerate(worlds_raw):
            key = f"search.worlds[{i}]"
            _check_world(p, key, _rel(p, key, w, "world"), {})
        worlds = tuple(worlds_raw)
    objective = raw.get("objective", "rms_error_m")
    from gcs.campaign.metrics import NUMERIC_METRICS

    if objective not in NUMERIC_METRICS:
        raise _fail(p, "search.objective", f"expected one of {list(NUMERIC_METRICS)}, got "
                    f"{objective!r}")
    penalty = raw.get("failed_penalty", 1.0)
    if not _number(penalty) or penalty < 0:
        raise _fail(p, "search.failed_penalty", f"expected a number >= 0, got {penalty!r}")
    for name in axes:
        if not name.startswith(("station.", "fly.")):
            raise _fail(p, f"axes.{name}", "a search varies station.KEY and fly.KEY axes; "
                        "seeds and worlds go in [search]")
    if not axes:
        raise _fail(p, "axes", "empty; a search needs at least one axis to tune")
    return SearchSpec(trials, tuple(seeds), worlds, objective, float(penalty))
