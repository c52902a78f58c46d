"""What each firmware does when its GCS or radio failsafe fires (pure decisions, no timers).

ArduCopter 4.x (`failsafe_gcs_on_event`, `failsafe_radio_on_event`, `do_failsafe_action`):
- FS_GCS_ENABLE 1 and 2 → RTL, 3 → SmartRTL else RTL, 4 → SmartRTL else LAND, 5 → LAND;
  FS_THR_ENABLE 1 and 2 → RTL, 3 → LAND, 4 → SmartRTL else RTL, 5 → SmartRTL else LAND.
- Then the exceptions, in order: disarmed → nothing ("GCS Failsafe"); should-disarm (STABILIZE
  with the throttle at zero, or landed in any mode) → disarm ("... - Disarming"); landing with
  FS_OPTIONS bit 3 → keep landing ("... - Continuing Landing"); GCS failsafe in a
  pilot-controlled mode (STABILIZE, ALT_HOLD) with FS_OPTIONS bit 4 — the 4.x default 16 —
  → nothing ("GCS Failsafe - Continuing Pilot Control"); otherwise the action ("GCS Failsafe").
- RTL and SmartRTL need a position (GPS): without one RTL becomes LAND, SmartRTL becomes RTL or
  LAND as its number says, and so LAND.
ArduCopter 3.2.1 (`failsafe_gcs_check`, `failsafe_radio_on_event`), no texts:
- GCS (any FS_GCS_ENABLE but 0): STABILIZE with the throttle at zero → disarm; otherwise RTL
  when home is more than WPNAV_RADIUS away (LAND when RTL is refused: no GPS), else LAND. It does
  not look at the land detector: a landed, armed vehicle in LAND is sent to RTL and climbs.
- Radio (FS_THR_ENABLE 1 RTL, 2 continue mission, 3 LAND): STABILIZE at zero throttle → disarm;
  landed in another mode → disarm; otherwise RTL (1, 2, home far) or LAND.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from sitl.autopilot.profile import AUTOPILOT_MODES, FlightMode

FS_OPTION_CONTINUE_IF_LANDING = 1 << 3
FS_OPTION_GCS_CONTINUE_IF_PILOT_CONTROL = 1 << 4


class Response(enum.Enum):
    """What the vehicle does."""

    NONE = "none"
    DISARM = "disarm"
    LAND = "land"  # set_mode_land_with_pause
    RTL = "rtl"
    SMART_RTL = "smart_rtl"


@dataclass(frozen=True)
class Situation:
    """The vehicle's state as the failsafe code sees it."""

    armed: bool
    mode: FlightMode
    landed: bool
    throttle_zero: bool
    gps: bool
    home_far: bool  # home more than WPNAV_RADIUS away


@dataclass(frozen=True)
class Decision:
    """The response, and the STATUSTEXT the firmware sends (None: no text)."""

    response: Response
    text: str | None


def _landing(s: Situation) -> bool:
    return s.mode is FlightMode.LAND


def _should_disarm(s: Situation) -> bool:
    if s.mode is FlightMode.STABILIZE:
        return s.throttle_zero or s.landed
    return s.landed


def _copter4(kind: str, wanted: Response, options: int, s: Situation) -> Decision:
    if not s.armed:
        return Decision(Response.NONE, f"{kind} Failsafe")
    if _should_disarm(s):
        return Decision(Response.DISARM, f"{kind} Failsafe - Disarming")
    if _landing(s) and options & FS_OPTION_CONTINUE_IF_LANDING:
        return Decision(Response.LAND, f"{kind} Failsafe - Continuing Landing")
    if (kind == "GCS" and options & FS_OPTION_GCS_CONTINUE_IF_PILOT_CONTROL
            and s.mode not in AUTOPILOT_MODES):
        return Decision(Response.NONE, "GCS Failsafe - Continuing Pilot Control")
    if not s.gps and wanted in (Response.RTL, Response.SMART_RTL):
        wanted = Response.LAND  # no position: SmartRTL and RTL both fail over to LAND
    return Decision(wanted, f"{kind} Failsafe")


# With a position SmartRTL always succeeds here, so 3 and 4 (4 and 5) differ only without one,
# where both end in LAND.
_GCS_ACTIONS = {1: Response.RTL, 2: Response.RTL, 3: Response.SMART_RTL, 4: Response.SMART_RTL,
                5: Response.LAND}
_RADIO_ACTIONS = {1: Response.RTL, 2: Response.RTL, 3: Response.LAND, 4: Response.SMART_RTL,
                  5: Response.SMART_RTL}


def gcs_copter4(fs_gcs_enable: int, fs_options: int, s: Situation) -> Decision:
    """4.x `failsafe_gcs_on_event` (FS_GCS_ENABLE not 0; unknown values act as RTL)."""
    return _copter4("GCS", _GCS_ACTIONS.get(fs_gcs_enable, Response.RTL), fs_options, s)


def radio_copter4(fs_thr_enable: int, fs_options: int, s: Situation) -> Decision:
    """4.x `failsafe_radio_on_event` (FS_THR_ENABLE not 0; unknown values act as LAND)."""
    return _copter4("Radio", _RADIO_ACTIONS.get(fs_thr_enable, Response.LAND), fs_options, s)


def _apm25_rtl_or_land(s: Situation) -> Response:
    return Response.RTL if s.home_far and s.gps else Response.LAND


def gcs_apm25(s: Situation) -> Decision:
    """3.2.1 `failsafe_gcs_check` once it fires (FS_GCS_ENABLE not 0; 2 only matters in AUTO)."""
    if not s.armed:
        return Decision(Response.NONE, None)
    if s.mode is FlightMode.STABILIZE and s.throttle_zero:
        return Decision(Response.DISARM, None)
    return Decision(_apm25_rtl_or_land(s), None)


def radio_apm25(fs_thr_enable: int, s: Situation) -> Decision:
    """3.2.1 `failsafe_radio_on_event`."""
    if not s.armed:
        return Decision(Response.NONE, None)
    if s.mode is FlightMode.STABILIZE:
        if s.throttle_zero:
            return Decision(Response.DISARM, None)
    elif s.landed:
        return Decision(Response.DISARM, None)
    if fs_thr_enable == 3:
        return Decision(Response.LAND, None)
    return Decision(_apm25_rtl_or_land(s), None)
