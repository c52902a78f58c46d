"""How a station lets go of its vehicle: release the overrides only where that is safe, and
ask for LAND when the loop itself has died with the vehicle possibly in the air."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from firmware_link.records import FlightMode, Heartbeat, RcCommand
from gcs.station.types import LinkLike
from gcs.supervisor import SupervisorState

EMERGENCY_LAND_S = 3.0
MODE_RESEND_S = 0.5
DISARM_REPORT_S = 30.0  # a vehicle in LAND still armed after this is reported, each period
STICK_MIN_US = 1000
LANDING_MODES = frozenset({FlightMode.LAND, FlightMode.RTL})


def let_go(link: LinkLike, state: SupervisorState, hb: Heartbeat | None) -> str:
    """Release the overrides if the vehicle is disarmed, in LAND, or the supervisor already let
    go; otherwise leave them (4.x would drop the throttle to the radio's minimum). The text to
    log, or '' when there is nothing to say."""
    disarmed = hb is not None and not hb.armed
    landing = hb is not None and hb.mode == FlightMode.LAND
    if state in (SupervisorState.RELEASED, SupervisorState.DISARMED) or disarmed or landing:
        try:
            link.release_overrides()
        except Exception as exc:  # the link may be what failed; the vehicle's failsafe rules
            return f"could not release overrides: {exc}"
        return ""
    if state is SupervisorState.SILENT:
        return ""
    return (f"left the vehicle armed in {state.value}: overrides not released, the vehicle's "
            "own failsafe takes over")


def emergency_land(link: LinkLike, throttle_us: int, period_s: float,
                   seconds: float = EMERGENCY_LAND_S,
                   speedup: float = 1.0) -> Heartbeat | str | None:
    """SET_MODE LAND every half second with `throttle_us` (the supervisor's safe throttle:
    hover aloft, minimum on the floor), level, until a heartbeat shows LAND or disarmed
    (returned), the time is up (None) or the link fails (its error text). Times are the
    vehicle's: a SITL run `speedup` times faster gets them that much sooner."""
    command = RcCommand(1500, 1500, throttle_us, 1500)
    end = time.monotonic() + seconds / speedup
    next_mode = 0.0
    try:
        while time.monotonic() < end:
            for r in link.poll():
                if isinstance(r, Heartbeat) and (not r.armed or r.mode == FlightMode.LAND):
                    return r
            if time.monotonic() >= next_mode:
                link.send_set_mode(FlightMode.LAND)
                next_mode = time.monotonic() + MODE_RESEND_S / speedup
            link.rc_override(command)
            time.sleep(period_s / speedup)  # a dead loop paces itself: there is no clock to wait on
    except Exception as exc:
        return str(exc) or type(exc).__name__
    return None


def stay_until_disarmed(link: Any, throttle_us: int, period_s: float, say: Callable[[str], None],
                        speedup: float = 1.0,
                        report_s: float = DISARM_REPORT_S) -> Heartbeat | str:
    """After LAND has shown: level, throttle minimum (LAND ignores the stick in the air;
    ArduCopter 3.2.1 disarms after LAND only once it is at minimum), heartbeats (the link sends
    them as it polls), until a heartbeat shows the vehicle disarmed (returned) or the link fails
    (its error text). Should a heartbeat show another mode (a failsafe's RTL, a pilot's
    STABILIZE), LAND is asked again, and outside LAND and RTL the throttle is `throttle_us` (the
    safe hover), not the minimum. A vehicle still armed `report_s` after is reported through
    `say`, again each period: nothing goes quiet on an armed vehicle (quiet, the landed 3.2.1 met
    its GCS failsafe, whose RTL took it back up to 14 m). Times are the vehicle's."""
    start = time.monotonic()
    next_report = start + report_s / speedup
    next_mode = 0.0
    mode = int(FlightMode.LAND)
    try:
        while True:
            for r in link.poll():
                if isinstance(r, Heartbeat):
                    if not r.armed:
                        return r
                    mode = r.mode
            now = time.monotonic()
            if mode != FlightMode.LAND and now >= next_mode:
                link.send_set_mode(FlightMode.LAND)
                next_mode = now + MODE_RESEND_S / speedup
            if now >= next_report:
                next_report = now + report_s / speedup
                say(f"STILL ARMED {(now - start) * speedup:.0f} s after LAND showed: throttle "
                    "minimum and heartbeats go on until it disarms (disarm it by hand, or "
                    "kill; this process stays)")
            thr = STICK_MIN_US if mode in LANDING_MODES else throttle_us
            link.rc_override(RcCommand(1500, 1500, thr, 1500))
            time.sleep(period_s / speedup)  # as emergency_land: no clock to wait on
    except Exception as exc:
        return str(exc) or type(exc).__name__
