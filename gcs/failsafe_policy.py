"""What the vehicle will do when the station goes silent: a pure prediction from its parameters.

The station lands a vehicle it cannot hear and then goes quiet; an uplink that dies leaves the
vehicle to its own failsafes with the last override in force. What they do was measured on the
real firmware (ECOSYSTEM.md, "What the real firmware does when the station goes silent"), and
`predict` follows the firmware's failsafe code for the modes the station flies (STABILIZE and
ALT_HOLD, both "pilot-controlled" to 4.x):

ArduCopter 4.x
- The GCS failsafe fires `FS_GCS_TIMEOUT` s after the GCS was last heard, if `FS_GCS_ENABLE` is
  not 0. With `FS_OPTIONS` bit 4 (16, the default: continue in pilot-controlled modes) it does
  nothing in STABILIZE / ALT_HOLD ("GCS Failsafe - Continuing Pilot Control").
- `RC_OVERRIDE_TIME` s after the last override the overrides lapse (-1: never, 0: ignored) and
  the throttle is the receiver's (measured: 1000 µs, the vehicle hit the floor at 3.5-4.4 m/s).
  With no receiver the last override stays in force and the radio failsafe (`FS_THR_ENABLE`)
  acts `RC_FS_TIMEOUT` s later. A failsafe that fires after the lapse comes too late.
- `FS_GCS_ENABLE`'s actions: 1 (2 outside AUTO) RTL, 3 SmartRTL or RTL, 4 SmartRTL or Land,
  5 Land, 6 DO_LAND_START or RTL, 7 Brake or Land; `FS_THR_ENABLE` numbers three of them
  differently (3 Land, 4 SmartRTL or RTL, 5 SmartRTL or Land). RTL, SmartRTL and
  Brake need a position; without one each falls back to Land. Land from a failsafe holds 4 s,
  then descends. RTL climbs to `RTL_ALT`; Brake holds the position and never lands.

ArduCopter 3.2.1
- The GCS failsafe (any `FS_GCS_ENABLE` but 0) fires a fixed 5 s after the last GCS heartbeat
  or override and clears the overrides; in STABILIZE / ALT_HOLD it picks RTL when home is more
  than 2 m away (WPNAV_RADIUS) and RTL is possible (a GPS position), LAND otherwise.
- Overrides never lapse while a receiver is present; with none, the radio failsafe
  (`FS_THR_ENABLE` 1/2 RTL-or-LAND as above, 3 LAND) fires 2 s after the last override.
- RTL climbs to `RTL_ALT` (cm; measured 14.0-14.3 m with the default 1500) before returning;
  `RTL_ALT` 0 returns at the current height, loiters `RTL_LOIT_TIME`, then descends to
  `RTL_ALT_FINAL` (0: lands; above 0: hovers there). 3.2.1 has no Land action, so RTL_ALT 0 (and
  RTL_ALT_FINAL 0) is the safe setting: RTL then holds and lands, without a climb.

The state: a GPS 3D fix (GPS_RAW_INT) is what lets RTL, SmartRTL and Brake navigate. Home needs
no input of its own: both firmwares set it at arming at the latest once they have a fix, and how
far from home the vehicle will be when the link dies cannot be known before the flight, so
3.2.1's "LAND within 2 m of home" is never counted on. Whatever the station could not learn
(GPS not reported, receiver unknown) is taken at its worst: a fix, and a receiver whose
throttle is anything.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Mapping
from dataclasses import dataclass, field

from firmware_link.records import Dialect, FlightMode

GPS_FIX_3D = 3  # GPS_RAW_INT.fix_type from which the firmware has a position
FS_OPTIONS_CONTINUE_PILOT = 16  # 4.x FS_OPTIONS bit 4: continue in pilot-controlled modes
LAND_ACTION = 5.0  # 4.x FS_GCS_ENABLE / FS_THR_ENABLE: Land
APM25_GCS_TIMEOUT_S = 5.0  # 3.2.1's FS_GCS_TIMEOUT_MS, a compile-time constant
APM25_RADIO_TIMEOUT_S = 2.0  # 3.2.1: no receiver, radio failsafe 2 s after the last override
LAND_PAUSE_S = 4.0  # 4.x: a failsafe's Land holds this long before it descends
FS_GCS_TIMEOUT_MIN_S = 2.0  # 4.x FS_GCS_TIMEOUT's lower bound
RC_OVERRIDE_TIME_DEFAULT_S = 3.0  # 4.x's default
FLOWN_MODES = (FlightMode.STABILIZE, FlightMode.ALT_HOLD)
# 4.x FS_THR_ENABLE values whose action FS_GCS_ENABLE numbers differently
RADIO_AS_GCS_ACTION = {3.0: 5.0, 4.0: 3.0, 5.0: 4.0}

PARAMETERS = {
    Dialect.COPTER4: ("FS_GCS_ENABLE", "FS_GCS_TIMEOUT", "FS_OPTIONS", "RC_OVERRIDE_TIME",
                      "FS_THR_ENABLE", "RC_FS_TIMEOUT", "RTL_ALT"),
    Dialect.APM25: ("FS_GCS_ENABLE", "FS_THR_ENABLE", "RTL_ALT", "RTL_ALT_FINAL"),
}


class Outcome(enum.Enum):
    """What a silent link ends in, from safe to unsafe."""

    LAND = "land"  # lands where it is
    HOLD_THEN_LAND = "hold then land"  # holds its height (or returns at it), then lands
    CLIMB = "climb"  # climbs before it lands (RTL to RTL_ALT)
    NAVIGATE = "navigate"  # flies somewhere by GPS (SmartRTL, DO_LAND_START)
    HOLD = "hold"  # holds and never lands (Brake, RTL_ALT_FINAL)
    KEEPS_FLYING = "keeps flying"  # no failsafe: the last override, or the receiver's throttle
    UNKNOWN = "unknown"  # a parameter or value the prediction cannot judge

    @property
    def safe(self) -> bool:
        """A landing, or a hold then a landing, without a climb."""
        return self in (Outcome.LAND, Outcome.HOLD_THEN_LAND)


@dataclass(frozen=True, slots=True)
class VehicleState:
    """What the station knows of the vehicle before flight (None: not known)."""

    gps_fix_type: int | None = None  # GPS_RAW_INT.fix_type
    receiver: bool | None = None  # an RC receiver present (the station cannot tell: None)

    @property
    def position(self) -> bool:
        """Whether RTL / SmartRTL / Brake may navigate (unknown counts as yes)."""
        return self.gps_fix_type is None or self.gps_fix_type >= GPS_FIX_3D

    @property
    def gps_words(self) -> str:
        """The GPS state as the refusal names it."""
        if self.gps_fix_type is None:
            return "GPS not reported"
        return "GPS 3D fix" if self.position else "no GPS fix"


@dataclass(frozen=True, slots=True)
class Prediction:
    """The outcome, the parameter that decides it, and what would make it safe."""

    outcome: Outcome
    param: str
    value: float | None
    what: str  # what the vehicle would do, after "on a silent link the vehicle "
    fix: Mapping[str, float] = field(default_factory=dict)  # everything --fix-failsafe sets
    fix_words: str = ""  # how to fix `param`, for the refusal line
    fixable: bool = False  # whether `fix` makes it safe

    @property
    def safe(self) -> bool:
        """Whether the station may fly."""
        return self.outcome.safe

    def line(self) -> str:
        """One line: parameter, value, what the vehicle would do, and the fix if unsafe."""
        value = "unreadable" if self.value is None else f"{self.value:g}"
        text = f"{self.param} {value}: on a silent link the vehicle {self.what}"
        if self.safe:
            return text
        how = f"{self.fix_words} or pass --fix-failsafe" if self.fixable else self.fix_words
        return f"{text}; {how}" if how else text


def required_parameters(dialect: Dialect) -> tuple[str, ...]:
    """What `predict` reads for this firmware."""
    return PARAMETERS[dialect]


def predict(dialect: Dialect, params: Mapping[str, float], state: VehicleState,
            mode: FlightMode = FlightMode.STABILIZE) -> Prediction:
    """What the vehicle does when the station falls silent while it flies `mode`. A missing
    parameter gives UNKNOWN naming it."""
    missing = [n for n in required_parameters(dialect) if n not in params]
    if missing:
        return Prediction(Outcome.UNKNOWN, missing[0], None, "cannot be predicted",
                          fix_words="read it again")
    if mode not in FLOWN_MODES:
        return Prediction(Outcome.UNKNOWN, "mode", float(mode), f"in {mode.name} cannot be "
                          "predicted (the station flies STABILIZE or ALT_HOLD)")
    fix = safe_settings(dialect, params, state)
    judge = _copter4 if dialect is Dialect.COPTER4 else _apm25
    p = judge(params, state, fix)
    if p.safe or not fix:
        return p
    return dataclasses.replace(p, fixable=judge({**params, **fix}, state, {}).safe)


def safe_settings(dialect: Dialect, params: Mapping[str, float],
                  state: VehicleState) -> dict[str, float]:
    """Every parameter change that makes the prediction safe (empty when it is, or when no
    change can): what `--fix-failsafe` sets."""
    g = params.get
    out: dict[str, float] = {}
    if dialect is Dialect.COPTER4:
        opts = int(g("FS_OPTIONS", 0.0))
        if opts & FS_OPTIONS_CONTINUE_PILOT:
            out["FS_OPTIONS"] = float(opts & ~FS_OPTIONS_CONTINUE_PILOT)
        action = g("FS_GCS_ENABLE", 0.0)
        if action == 0 or not _copter4_action(action, state, params)[0].safe:
            out["FS_GCS_ENABLE"] = LAND_ACTION
        lapse, timeout = g("RC_OVERRIDE_TIME", 0.0), g("FS_GCS_TIMEOUT", 0.0)
        if 0 <= lapse <= FS_GCS_TIMEOUT_MIN_S:  # ignored, or too short for any GCS timeout
            lapse = out["RC_OVERRIDE_TIME"] = RC_OVERRIDE_TIME_DEFAULT_S
        if lapse > 0 and timeout >= lapse:
            # the shortest timeout: the last override is flown blind until the failsafe acts
            out["FS_GCS_TIMEOUT"] = FS_GCS_TIMEOUT_MIN_S
        return out
    if g("FS_GCS_ENABLE", 0.0) == 0:
        out["FS_GCS_ENABLE"] = 1.0
    if state.position and g("RTL_ALT", 0.0) > 0:
        out["RTL_ALT"] = 0.0
    if state.position and g("RTL_ALT_FINAL", 0.0) > 0:
        out["RTL_ALT_FINAL"] = 0.0
    return out


def _copter4(p: Mapping[str, float], state: VehicleState, fix: dict[str, float]) -> Prediction:
    action, opts = p["FS_GCS_ENABLE"], int(p["FS_OPTIONS"])
    lapse, timeout = p["RC_OVERRIDE_TIME"], p["FS_GCS_TIMEOUT"]
    if lapse == 0:
        return Prediction(Outcome.UNKNOWN, "RC_OVERRIDE_TIME", lapse, "ignores the station's "
                          "sticks (0: overrides disabled)", fix, "set RC_OVERRIDE_TIME 3")
    if action == 0:
        outcome, what = _copter4_no_gcs_failsafe(p, state, "no GCS failsafe")
        return Prediction(outcome, "FS_GCS_ENABLE", action, what, fix,
                          f"set FS_GCS_ENABLE {LAND_ACTION:g}")
    if opts & FS_OPTIONS_CONTINUE_PILOT:
        outcome, what = _copter4_no_gcs_failsafe(
            p, state, "bit 4: continue in pilot-controlled modes")
        return Prediction(outcome, "FS_OPTIONS", float(opts), what, fix, "set bit 4 off")
    if lapse > 0 and timeout >= lapse:
        return Prediction(Outcome.KEEPS_FLYING, "FS_GCS_TIMEOUT", timeout,
                          f"keeps flying on the receiver's throttle from {lapse:g} s, when the "
                          f"overrides lapse (RC_OVERRIDE_TIME {lapse:g}), before its failsafe at "
                          f"{timeout:g} s", fix,
                          f"set FS_GCS_TIMEOUT under RC_OVERRIDE_TIME {lapse:g}"
                          if lapse > FS_GCS_TIMEOUT_MIN_S else
                          f"set RC_OVERRIDE_TIME over FS_GCS_TIMEOUT's least "
                          f"{FS_GCS_TIMEOUT_MIN_S:g} s")
    outcome, what = _copter4_action(action, state, p)
    return Prediction(outcome, "FS_GCS_ENABLE", action, f"after {timeout:g} s {what}", fix,
                      f"set FS_GCS_ENABLE {LAND_ACTION:g}")


def _copter4_no_gcs_failsafe(p: Mapping[str, float], state: VehicleState,
                             why: str) -> tuple[Outcome, str]:
    """No GCS failsafe acts: the overrides lapse, or they never do."""
    lapse = p["RC_OVERRIDE_TIME"]
    if lapse < 0:
        return Outcome.KEEPS_FLYING, f"keeps flying its last override ({why}; " \
                                     "RC_OVERRIDE_TIME -1: overrides never lapse)"
    if state.receiver is not False:
        return Outcome.KEEPS_FLYING, f"keeps flying on the receiver's throttle ({why})"
    radio = p["FS_THR_ENABLE"]
    if radio == 0:
        return Outcome.KEEPS_FLYING, f"keeps flying its last override ({why}; no receiver, " \
                                     "FS_THR_ENABLE 0)"
    outcome, what = _copter4_action(RADIO_AS_GCS_ACTION.get(radio, radio), state, p)
    after = lapse + p["RC_FS_TIMEOUT"]
    return outcome, f"after {after:g} s {what} ({why}; no receiver: radio failsafe " \
                    f"FS_THR_ENABLE {radio:g})"


def _copter4_action(action: float, state: VehicleState,
                    p: Mapping[str, float]) -> tuple[Outcome, str]:
    """A 4.x failsafe action (FS_GCS_ENABLE / FS_THR_ENABLE value) in a pilot-controlled mode."""
    land = (Outcome.HOLD_THEN_LAND, f"holds {LAND_PAUSE_S:g} s, then lands")
    pos = state.position
    gps = state.gps_words
    if action == LAND_ACTION:
        return land
    if action in (1.0, 2.0, 6.0):  # RTL (6: no DO_LAND_START in a mission flown by sticks)
        if not pos:
            return land[0], f"{land[1]} (RTL needs a position: {gps})"
        rtl_alt = p["RTL_ALT"]
        if rtl_alt > 0:
            return Outcome.CLIMB, f"climbs to RTL_ALT {rtl_alt / 100.0:g} m in RTL ({gps})"
        return Outcome.NAVIGATE, f"flies home by GPS in RTL ({gps})"
    if action in (3.0, 4.0):  # SmartRTL, or RTL / Land without a position
        if not pos:
            return land[0], f"{land[1]} (SmartRTL needs a position: {gps})"
        return Outcome.NAVIGATE, f"flies its path back by GPS in SmartRTL ({gps})"
    if action == 7.0:
        if not pos:
            return land[0], f"{land[1]} (Brake needs a position: {gps})"
        return Outcome.HOLD, f"brakes and holds its position, never landing ({gps})"
    return Outcome.UNKNOWN, f"does what action {action:g} does (not one this station knows)"


def _apm25(p: Mapping[str, float], state: VehicleState, fix: dict[str, float]) -> Prediction:
    gcs_on = p["FS_GCS_ENABLE"] != 0
    radio = p["FS_THR_ENABLE"]
    if not gcs_on:
        if state.receiver is False and radio != 0:
            outcome, what, param = _apm25_rtl_or_land(p, state, radio == 3.0)
            return Prediction(outcome, param, p[param], f"after {APM25_RADIO_TIMEOUT_S:g} s "
                              f"{what} (no receiver: radio failsafe "
                              f"FS_THR_ENABLE {radio:g})", fix, _apm25_fix_words(param))
        return Prediction(Outcome.KEEPS_FLYING, "FS_GCS_ENABLE", 0.0, "keeps flying its last "
                          "override (no GCS failsafe; 3.2.1's overrides never lapse)", fix,
                          "set FS_GCS_ENABLE 1")
    # with no receiver the radio failsafe may come first (2 s), choosing as the GCS one does
    # unless FS_THR_ENABLE is 3 (LAND): the GCS failsafe's RTL decides the worst case
    outcome, what, param = _apm25_rtl_or_land(p, state, False)
    return Prediction(outcome, param, p[param], f"after {APM25_GCS_TIMEOUT_S:g} s {what}",
                      fix, _apm25_fix_words(param))


def _apm25_rtl_or_land(p: Mapping[str, float], state: VehicleState,
                       land_only: bool) -> tuple[Outcome, str, str]:
    """3.2.1's choice in STABILIZE / ALT_HOLD: RTL when it can (home may be over 2 m away),
    LAND otherwise; the parameter that decides it."""
    if land_only or not state.position:
        why = "FS_THR_ENABLE 3" if land_only else f"RTL needs a position: {state.gps_words}"
        return Outcome.LAND, f"lands ({why})", "FS_GCS_ENABLE"
    rtl_alt, final = p["RTL_ALT"], p["RTL_ALT_FINAL"]
    if rtl_alt > 0:
        return (Outcome.CLIMB, f"climbs to RTL_ALT {rtl_alt / 100.0:g} m in RTL "
                f"({state.gps_words})", "RTL_ALT")
    if final > 0:
        return (Outcome.HOLD, f"returns in RTL and hovers at RTL_ALT_FINAL {final / 100.0:g} m, "
                "never landing", "RTL_ALT_FINAL")
    return (Outcome.HOLD_THEN_LAND, "returns home at its height in RTL (RTL_ALT 0), loiters, "
            f"then lands ({state.gps_words})", "RTL_ALT")


def _apm25_fix_words(param: str) -> str:
    return {"RTL_ALT": "set RTL_ALT 0 (return at the current height)",
            "RTL_ALT_FINAL": "set RTL_ALT_FINAL 0 (land at the end of RTL)"}.get(param, "")
