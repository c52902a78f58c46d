"""What one tick writes to the recording, and the IMU averaging a rerun must repeat exactly."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from firmware_link.records import (
    Attitude,
    Barometer,
    Imu,
    MocapPose,
    Rangefinder,
    TelemetryRecord,
)
from gcs import topics
from gcs.control.altitude_controller import AltControlOutput
from gcs.control.position_controller import PositionCommand
from gcs.estimation import AltEstimate
from gcs.station.loop import TickTiming
from gcs.station.types import LoopSample, TickInputs
from gcs.supervisor import Intent, LinkHealth, SupervisorOutput, VehicleStatus


@dataclass(frozen=True, slots=True)
class TickRecord:
    """Everything one tick consumed and decided."""

    t_s: float
    tick: int
    dt_s: float
    estimate: AltEstimate
    records: list[TelemetryRecord]
    intents: list[Intent]
    status: VehicleStatus
    out: SupervisorOutput
    at_rest: bool
    alt: AltControlOutput | None
    position: PositionCommand | None
    timing: TickTiming | None


def record_tick(rec: Any, r: TickRecord) -> None:
    """Write the tick: its intents, its inputs (for a rerun), the supervisor's transitions, the
    estimate, the controllers' outputs, the override sent and the loop's timing."""
    t_s, records = r.t_s, r.records
    for it in r.intents:
        rec.put(topics.INTENT, t_s, it)
    s = r.status
    rec.put(topics.TICK, t_s, TickInputs(
        tick=r.tick, t_s=t_s, dt_s=r.dt_s,
        imu_n=sum(isinstance(x, Imu) for x in records),
        rangefinder_n=sum(isinstance(x, Rangefinder) for x in records),
        attitude_n=sum(isinstance(x, Attitude) for x in records),
        mocap_n=sum(isinstance(x, MocapPose) for x in records),
        baro_n=sum(isinstance(x, Barometer) for x in records),
        intent_n=len(r.intents), at_rest=r.at_rest, vehicle_seen=s.seen, armed=s.armed,
        vehicle_mode=s.mode, heartbeat_t_s=s.heartbeat_t_s, frame_age_s=s.frame_age_s,
        state=r.out.state, link_lost=r.out.link is LinkHealth.LOST))
    for tr in r.out.transitions:
        rec.put(topics.SUPERVISOR, t_s, tr)
    rec.put(topics.ESTIMATE, t_s, r.estimate)
    if r.alt is not None:
        rec.put(topics.ALT_CONTROLLER, t_s, r.alt)
    if r.position is not None:
        rec.put(topics.POSITION_CONTROLLER, t_s, r.position)
    if r.out.command is not None:
        rec.put(topics.RC_OVERRIDE, t_s, r.out.command)
    last = r.timing
    if last is not None:
        rec.put(topics.LOOP, t_s, LoopSample(
            tick=last.k, period_ms=last.period_s * 1e3, jitter_ms=last.jitter_s * 1e3,
            lateness_ms=last.lateness_s * 1e3, compute_ms=last.compute_s * 1e3,
            overrun=last.overrun))
