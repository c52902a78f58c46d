"""One fault-search run: `fly --lockstep` with a seed and a schedule, then the SITL alone for a
few seconds (what happens after the station let go counts too), then the properties' margins.

It never raises for a flight that went wrong: a failed flight is what a search looks for.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gcs.errors import FlightFailed, QuadgcsError
from gcs.flight_plan import FlightPlan
from gcs.station.session import SessionOptions
from lab.faultsearch.inject import FaultPlan, RunCapped, install
from lab.faultsearch.properties import PROPERTIES, Margin, evaluate
from lab.faultsearch.schedule import Schedule, flight_span_s
from lab.faultsearch.trace import Trace

AFTER_S = 2.0  # the SITL runs on alone at least this long after `fly` returned
SETTLED_S = 1.0  # ... until its vehicle has been down and disarmed this long
AFTER_MAX_S = 40.0  # ... or this long at most (a landing's documented time and some)


@dataclass(frozen=True, slots=True)
class SearchFlight:
    """What every run of a search flies (short: a search flies thousands)."""

    profile: str = "apm25"
    world: Path | None = None
    plan: FlightPlan = field(default_factory=lambda: FlightPlan(
        alt_m=1.0, hold_s=3.0, settle_s=1.0, step_m=0.3, step_observe_s=2.0))
    fix_failsafe: bool = False
    properties: tuple[str, ...] = PROPERTIES


@dataclass(frozen=True, slots=True)
class RunResult:
    """A run's verdict: every margin, the smallest, and fly's own word."""

    seed: int
    schedule: Schedule
    margins: tuple[Margin, ...]
    exit_ok: bool
    exit_reason: str
    sim_s: float
    wall_s: float

    @property
    def worst(self) -> Margin:
        """The property closest to violated (or most violated)."""
        return min(self.margins, key=lambda m: m.margin)

    @property
    def violated(self) -> tuple[Margin, ...]:
        """The properties this run violated."""
        return tuple(m for m in self.margins if m.margin < 0.0)


def _settled(trace: Trace) -> bool:
    t = trace.truth
    if not t or t[-1].armed or not t[-1].on_ground:
        return False
    since = next((u.t_s for u in reversed(t) if u.armed or not u.on_ground), t[0].t_s)
    return t[-1].t_s - since >= SETTLED_S


def fly_schedule(flight: SearchFlight, seed: int, schedule: Schedule) -> RunResult:
    """Fly `schedule` once on `seed`; the properties' margins."""
    from gcs.commands.fly import fly_session
    from gcs.lockstep_session import LockstepSession

    install()
    w0 = time.perf_counter()
    cap_s = flight_span_s(flight.plan)
    plan = FaultPlan(schedule, seed, cap_s)
    trace = plan.trace
    options = SessionOptions(command="fly", profile=flight.profile, world=flight.world,
                             seed=seed, record=False, fix_failsafe=flight.fix_failsafe,
                             )
    session = LockstepSession(options, faults={"schedule": plan})
    sitl = session.sitl.sitl
    try:
        with session:
            try:
                fly_session(session, flight.plan, pilot_signals=False)
                trace.exit_ok = True
            except FlightFailed as exc:
                trace.exit_reason = str(exc)
            except QuadgcsError as exc:
                trace.exit_reason = f"{type(exc).__name__}: {exc}"
            trace.flight_end_s = sitl.t_s
        # leaving the session landed what flew; the vehicle then has only its own firmware
        end = min(sitl.t_s + AFTER_MAX_S, cap_s)
        until = sitl.t_s + AFTER_S
        while sitl.t_s < end and (sitl.t_s < until or not _settled(trace)):
            sitl.advance_to(min(sitl.t_s + 0.5, end))
    except RunCapped as exc:  # the run's verdict is in its trace (never disarmed, say)
        trace.exit_reason = trace.exit_reason or str(exc)
        trace.flight_end_s = trace.flight_end_s or plan.stop_at_s
    begun = [(b, f.length_s, f.kind) for f in schedule.faults
             if (b := f.begins_s(trace.anchors)) is not None and b <= sitl.t_s]
    margins = evaluate(trace, begun, flight.properties)
    return RunResult(seed, schedule, tuple(margins), trace.exit_ok, trace.exit_reason,
                     sitl.t_s, time.perf_counter() - w0)


def result_row(r: RunResult) -> dict[str, Any]:
    """A run as a results row: the closest property and its margin, every margin, fly's word."""
    worst = r.worst
    row: dict[str, Any] = {"seed": r.seed, "property": worst.name, "margin": worst.margin,
                           "note": worst.note, "violated": ",".join(m.name for m in r.violated),
                           "exit_ok": r.exit_ok, "exit_reason": r.exit_reason[:200],
                           "sim_s": r.sim_s, "wall_s": r.wall_s}
    for m in r.margins:
        row[f"margin.{m.name}"] = m.margin
        row[f"note.{m.name}"] = m.note
    return row
