"""`kind = "fault-search"` campaign files: the flight, the budget, the faults and the properties.

    name = "fault_search_apm25"     # default: the file's stem
    kind = "fault-search"
    runs = 2000                     # the budget
    random_runs = 400               # sampled at random before TPE (default: a fifth, >= 10)
    sample_seed = 0                 # the sampler's seed
    shrink_runs = 8                 # flights spent shrinking each violation (0: none)

    [fly]                           # each run: `quadgcs fly --lockstep` with these
    profile = "apm25"
    world = "../worlds/empty_room.toml"
    alt_m = 0.6
    hold_s = 1.0
    step_m = 0.2
    step_watch_s = 1.5
    fix_failsafe = false

    [faults]                        # what the search varies (every key has a default)
    kinds = ["fade_up", "pilot_kill"]   # default: every kind (lab.faultsearch.schedule.KINDS)
    anchors = ["time", "hold"]          # default: a time over the whole flight and every phase
    per_run = 2                         # faults in one run, at most
    max_length_s = 10.0
    seeds = [1, 10000]                  # the seed range
    properties = ["kill", "impact"]     # default: every property

Every problem is one line naming the file, the key and what was expected (`CampaignError`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gcs.flight_plan import FlightPlan
from lab.campaign.types import PROFILES, CampaignError
from lab.faultsearch.properties import PROPERTIES
from lab.faultsearch.runner import SearchFlight
from lab.faultsearch.schedule import KINDS, PHASES
from lab.faultsearch.space import TIME, Space
from worldfile import read_toml

KIND = "fault-search"
TOP_KEYS = ("name", "kind", "runs", "random_runs", "sample_seed", "shrink_runs", "fly", "faults")
FLY_KEYS = ("profile", "world", "alt_m", "hold_s", "step_m", "step_watch_s", "fix_failsafe")
FAULT_KEYS = ("kinds", "anchors", "per_run", "max_length_s", "seeds", "properties")


@dataclass(frozen=True, slots=True)
class FaultCampaign:
    """A checked fault-search campaign file."""

    path: Path
    name: str
    runs: int
    random_runs: int | None
    sample_seed: int
    shrink_runs: int
    flight: SearchFlight
    space: Space
    world: str | None  # as the file writes it (for the reproduction command)


def is_fault_search(path: Path) -> bool:
    """Whether a campaign file is a fault search (False when it cannot be read: the campaign
    loader then says why)."""
    try:
        return read_toml(path, error=CampaignError).get("kind") == KIND
    except CampaignError:
        return False


def _fail(path: Path, key: str, problem: str) -> CampaignError:
    return CampaignError(f"{path}: {key}: {problem}")


def _int(p: Path, table: dict[str, Any], key: str, default: int | None, lo: int,
         where: str = "") -> int | None:
    v = table.get(key, default)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, int) or v < lo:
        raise _fail(p, where + key, f"expected an integer >= {lo}, got {v!r}")
    return v


def _num(p: Path, table: dict[str, Any], key: str, default: float, where: str) -> float:
    v = table.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or v <= 0:
        raise _fail(p, where + key, f"expected a number > 0, got {v!r}")
    return float(v)


def _names(p: Path, table: dict[str, Any], key: str, allowed: tuple[str, ...]) -> tuple[str, ...]:
    v = table.get(key, list(allowed))
    if not isinstance(v, list) or not v or not all(x in allowed for x in v):
        raise _fail(p, f"faults.{key}", f"expected a non-empty list among {', '.join(allowed)}, "
                    f"got {v!r}")
    return tuple(v)


def _table(p: Path, data: dict[str, Any], key: str, keys: tuple[str, ...]) -> dict[str, Any]:
    t = data.get(key, {})
    if not isinstance(t, dict):
        raise _fail(p, key, "expected a table")
    for k in t:
        if k not in keys:
            raise _fail(p, f"{key}.{k}", f"unknown key; expected one of {', '.join(keys)}")
    return t


def _flight(p: Path, fly: dict[str, Any]) -> tuple[SearchFlight, str | None]:
    profile = fly.get("profile", "apm25")
    if profile not in PROFILES:
        raise _fail(p, "fly.profile", f"expected one of {list(PROFILES)}, got {profile!r}")
    world = fly.get("world")
    world_path = None
    if world is not None:
        world_path = p.parent.resolve() / str(world)
        if not isinstance(world, str) or not world_path.is_file():
            raise _fail(p, "fly.world", f"expected a path to a world file, got {world!r}")
    fix = fly.get("fix_failsafe", profile == "copter4")
    if not isinstance(fix, bool):
        raise _fail(p, "fly.fix_failsafe", f"expected true or false, got {fix!r}")
    try:
        plan = FlightPlan(alt_m=_num(p, fly, "alt_m", 0.6, "fly."),
                          hold_s=_num(p, fly, "hold_s", 1.0, "fly."),
                          step_m=float(fly.get("step_m", 0.2)),
                          step_observe_s=_num(p, fly, "step_watch_s", 1.5, "fly."))
    except (ValueError, TypeError) as exc:
        raise _fail(p, "fly", str(exc)) from None
    return SearchFlight(profile, world_path, plan, fix), world


def load_fault_campaign(path: str | Path) -> FaultCampaign:
    """Read and check a fault-search campaign file; CampaignError (one line) otherwise."""
    p = Path(path)
    data = read_toml(p, label=str(p), noun="campaign file", error=CampaignError)
    for key in data:
        if key not in TOP_KEYS:
            raise _fail(p, key, f"unknown key; expected one of {', '.join(TOP_KEYS)}")
    if data.get("kind") != KIND:
        raise _fail(p, "kind", f"expected {KIND!r}, got {data.get('kind')!r}")
    name = data.get("name", p.stem)
    if not isinstance(name, str) or not name or "/" in name:
        raise _fail(p, "name", f"expected a name without '/', got {name!r}")
    runs = _int(p, data, "runs", None, 1)
    if runs is None:
        raise _fail(p, "runs", "missing; expected the budget, an integer >= 1")
    flight, world = _flight(p, _table(p, data, "fly", FLY_KEYS))
    f = _table(p, data, "faults", FAULT_KEYS)
    seeds = f.get("seeds", [1, 10_000])
    if (not isinstance(seeds, list) or len(seeds) != 2
            or not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in seeds)
            or seeds[0] > seeds[1]):
        raise _fail(p, "faults.seeds", f"expected [first, last] integers >= 0, got {seeds!r}")
    space = Space(kinds=_names(p, f, "kinds", tuple(KINDS)),
                  anchors=_names(p, f, "anchors", (TIME, *PHASES)),
                  slots=_int(p, f, "per_run", 2, 1, "faults.") or 2,
                  max_length_s=_num(p, f, "max_length_s", 10.0, "faults."),
                  seeds=(seeds[0], seeds[1]))
    props = _names(p, f, "properties", PROPERTIES)
    flight = SearchFlight(flight.profile, flight.world, flight.plan, flight.fix_failsafe, props)
    return FaultCampaign(p, name, runs, _int(p, data, "random_runs", None, 0),
                         _int(p, data, "sample_seed", 0, 0) or 0,
                         _int(p, data, "shrink_runs", 8, 0) or 0, flight, space, world)
