"""The station's snapshot, as of one tick: what the flight core decided and the link said."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TypeVar

from firmware_link.records import (
    Attitude,
    Heartbeat,
    Imu,
    MocapPose,
    Rangefinder,
    SimTruth,
    TelemetryRecord,
)
from firmware_link.stats import LinkStats
from gcs.core.flight_core import FlightCore
from gcs.station.intents import STICK_MIN_US
from gcs.station.loop import LoopStats
from gcs.station.types import StationEvent, StationSnapshot, control_mode
from gcs.supervisor import LinkHealth, Outcome, SupervisorState

R = TypeVar("R", bound=TelemetryRecord)


def _newest(latest: Mapping[type, TelemetryRecord], cls: type[R]) -> R | None:
    r = latest.get(cls)
    return r if isinstance(r, cls) else None


def make_snapshot(t_s: float, k: int, *, running: bool, core: FlightCore,
                  latest: dict[type, TelemetryRecord], loop: LoopStats, link_stats: LinkStats,
                  events: tuple[StationEvent, ...], listener_errors: int,
                  outcomes: tuple[Outcome, ...]) -> StationSnapshot:
    """The snapshot at tick `k` (-1 before the first); `latest` is the station's own, copied."""
    sup = core.supervisor
    latest = dict(latest)
    hb = _newest(latest, Heartbeat)
    last = core.last
    out = last.supervisor if last is not None else None
    estimate = last.estimate if last is not None else None
    return StationSnapshot(
        t_s=t_s,
        tick=k,
        running=running,
        mode=control_mode(sup.state, sup.pos_setpoint is not None),
        state=sup.state,
        link_health=out.link if out is not None else LinkHealth.OK,
        armed=bool(hb and hb.armed),
        vehicle_mode=hb.mode if hb else -1,
        link_lost=out is not None and out.link is LinkHealth.LOST,
        heartbeat=hb,
        attitude=_newest(latest, Attitude),
        imu=_newest(latest, Imu),
        rangefinder=_newest(latest, Rangefinder),
        mocap=_newest(latest, MocapPose),
        truth=_newest(latest, SimTruth),
        latest=latest,
        estimate=estimate,
        alt_setpoint_m=out.alt_setpoint_m if out is not None else None,
        position_setpoint=sup.pos_setpoint if sup.state is SupervisorState.HOLD else None,
        alt=sup.alt,
        position=sup.position,
        command=sup.command,
        sticks=sup.sticks,
        throttle_gate_us=out.throttle_gate_us if out is not None else None,
        hover_throttle=core.alt_ctrl.hover_throttle,
        loop=loop,
        link_stats=link_stats,
        events=events,
        listener_errors=listener_errors,
        link_down_s=last.link_down_s if last is not None else 0.0,
        safe_throttle_us=(sup.safe_throttle_us(estimate.alt_m)
                          if estimate is not None else STICK_MIN_US),
        outcomes=outcomes,
    )
