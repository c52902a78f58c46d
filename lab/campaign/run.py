"""One campaign run: `fly --lockstep` with the run's world, station and plan, as one row.

This is the function a worker runs. It never raises for a flight that went wrong: a refusal, a
failed flight or a bad value is a row with its reason, so one run cannot end a campaign.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from gcs.config import config_from_table
from gcs.flight import FlightPlan
from gcs.station.session import SessionOptions
from lab.campaign.metrics import failed_row, flown_row
from lab.campaign.tables import set_dotted, station_table, world_table
from lab.campaign.types import BaseFlight, BaseMission
from lab.lockstep import install
from sitl import native


@dataclass(frozen=True, slots=True)
class RunSpec:
    """One run: its id (a digest of the base flight and the values) and the axes' values."""

    run_id: str
    values: dict[str, Any]


def run_id(base: BaseFlight | BaseMission, values: dict[str, Any]) -> str:
    """The same base flight and values give the same id (what resume recognises)."""
    fields = {k: str(v) for k, v in asdict(base).items() if k != "root"}
    text = json.dumps({"base": fields, "values": values}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def make_run(base: BaseFlight | BaseMission, values: dict[str, Any]) -> RunSpec:
    """A RunSpec for these values."""
    return RunSpec(run_id(base, values), dict(values))


def _split(values: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any], dict[str, float],
                                            dict[str, Any]]:
    world: dict[str, Any] = {}
    station: dict[str, Any] = {}
    fly: dict[str, float] = {}
    link: dict[str, Any] = {}
    for name, v in values.items():
        if name.startswith("world."):
            set_dotted(world, name.removeprefix("world."), v)
        elif name.startswith("station."):
            set_dotted(station, name.removeprefix("station."), v)
        elif name.startswith("fly."):
            fly[name.removeprefix("fly.")] = float(v)
        elif name.startswith("link."):
            link[name.removeprefix("link.")] = v
    return world, station, fly, link


def fly_run(base: BaseFlight, run: RunSpec, output: Path, campaign: str) -> dict[str, Any]:
    """Fly one run in lockstep; its row (status "ok", or "failed" with the reason)."""
    from gcs.commands.fly import fly_session
    from gcs.lockstep_session import LockstepSession

    install()  # a worker process flies lockstep on the bundled SITL

    c0, w0 = time.process_time(), time.perf_counter()
    values = run.values
    try:
        world_over, station_over, fly_over, faults = _split(values)
        world_path = base.resolve(values["world"]) if "world" in values else base.world_path
        config = config_from_table(station_table(base.config_path, station_over))
        plan = FlightPlan(alt_m=fly_over.get("alt_m", base.alt_m),
                          hold_s=fly_over.get("hold_s", base.hold_s),
                          step_m=fly_over.get("step_m", base.step_m),
                          takeoff_delay_s=fly_over.get("takeoff_delay_s", base.takeoff_delay_s))
        options = SessionOptions(
            command="fly", profile=str(values.get("profile", base.profile)), world=world_path,
            seed=int(values.get("seed", 0)), record=base.record, fix_failsafe=base.fix_failsafe,
            output=output / "flights" / f"{run.run_id}.mcap",
            metadata={"campaign": campaign, "run_id": run.run_id})
        session = LockstepSession(options, world=world_table(world_path, world_over),
                                  config=config, faults=faults or None)
        with session:
            summary = fly_session(session, plan, pilot_signals=False)
            sim_s = session.clock.now_s()
        row = flown_row(run.run_id, values, summary)
        row["sim_s"] = sim_s
        if base.record:
            row.update(recording_checks(options.output))
    except Exception as exc:  # a failed run is a row with its reason, never the campaign's end
        row = failed_row(run.run_id, values, failure_text(exc))
    return stamped(row, c0, w0)


def recording_checks(path: Path) -> dict[str, float]:
    """A run's `logs check` metrics as its row's `check.<key>` columns: what `quadgcs logs check
    --against` places a flight among."""
    from gcs.flight_check import gather_file
    from logs.check import measure
    from logs.check.against import check_columns

    return check_columns(measure(gather_file(path)))


# errors whose text says what went wrong; any other gets its type's name in front
_SPOKEN = ("FlightFailed", "MissionFailed", "UsageError", "RuntimeFault", "LinkError",
           "ParamError", "CampaignError")


def failure_text(exc: Exception) -> str:
    """A failed run's reason, as one line."""
    text = str(exc) or type(exc).__name__
    return text if type(exc).__name__ in _SPOKEN else f"{type(exc).__name__}: {text}"


def stamped(row: dict[str, Any], c0: float, w0: float) -> dict[str, Any]:
    """The row with the run's CPU and wall time since (c0, w0), the worker that ran it and
    which SITL it flew (compiled or interpreted: the CPU time depends on it)."""
    row["cpu_s"] = time.process_time() - c0
    row["wall_s"] = time.perf_counter() - w0
    row["worker"] = f"{os.uname().nodename}:{os.getpid()}"
    row["sitl"] = native.build_kind()
    return row
