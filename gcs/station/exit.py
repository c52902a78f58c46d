"""How a station lets go of its vehicle: release the overrides only where that is safe, and
ask for LAND when the loop itself has died with the vehicle possibly in the air."""

from __future__ import annotations

import time

from firmware_link.records import FlightMode, Heartbeat, RcCommand
from gcs.station.types import LinkLike
from gcs.supervisor import SupervisorState

EMERGENCY_LAND_S = 3.0
MODE_RESEND_S = 0.5


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
