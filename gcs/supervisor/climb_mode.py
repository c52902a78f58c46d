"""The supervisor's climb-rate hold: PC control flown in the firmware's ALT_HOLD.

With a `ClimbRateHold` the supervisor's PC control (spool-up, take-off, hold) runs in ALT_HOLD
instead of STABILIZE, and every override it sends is a climb rate (`gcs.control.climb_rate_hold`):
- Spool-up: armed in STABILIZE with the throttle at minimum (both firmwares arm only so), the
  station asks for ALT_HOLD and keeps the stick at minimum (on the floor ALT_HOLD stays landed:
  a climb rate of zero or less does not take off) until the motors have spooled and a heartbeat
  shows ALT_HOLD; no ALT_HOLD within `MODE_WAIT_S` ends the take-off.
- Take-off: a climb rate asked from the floor, open loop while the estimate is in the
  rangefinder's blind band (the firmware's velocity loop does the climbing), then the closed loop
  tapers it to zero at the set point; airborne is the estimate climbing out of the blind band.
- Hold: the climb rate toward the set point; steady, mid-stick ("hold this height").
- A telemetry gap, a lost link: mid-stick in ALT_HOLD, the firmware holds its height until the
  station's LAND or its own failsafe lands it (`safe_throttle_us`).
- Any other mode once ALT_HOLD has been seen (a failsafe's LAND or RTL, the pilot's switch) ends
  PC control, as leaving STABILIZE does for the direct hold.
"""

from __future__ import annotations

from firmware_link.records import FlightMode, RcCommand
from gcs.control.climb_rate_hold import ClimbRateHold, ClimbRateOutput
from gcs.supervisor.liftoff import LiftoffDetector
from gcs.supervisor.outcomes import OutcomeKind
from gcs.supervisor.params import SupervisorParams
from gcs.supervisor.types import (
    STICK_MID_US,
    STICK_MIN_US,
    Action,
    ActionKind,
    Level,
    LinkHealth,
    SupervisorState,
    TickIn,
)

S = SupervisorState
MODE_WAIT_S = 5.0  # after the spool-up, for a heartbeat showing ALT_HOLD
LEVEL_MIN = RcCommand(STICK_MID_US, STICK_MID_US, STICK_MIN_US, STICK_MID_US)
LEVEL_MID = RcCommand(STICK_MID_US, STICK_MID_US, STICK_MID_US, STICK_MID_US)


def pc_mode(climb: ClimbRateHold | None) -> FlightMode:
    """The mode the station's own control flies in."""
    return FlightMode.STABILIZE if climb is None else FlightMode.ALT_HOLD


class ClimbModeCommands:
    """The climb-rate hold's part of the supervisor (mixed into `StateCommands`)."""

    # what the state machine provides (gcs.supervisor.commands.StateCommands)
    p: SupervisorParams
    climb: ClimbRateHold | None
    climb_out: ClimbRateOutput | None
    state: SupervisorState
    since_s: float
    requested_mode: int | None
    _asked_why: str
    _t: float
    _armed_at_s: float
    _link: LinkHealth
    alt_target_m: float | None
    alt_rate_mps: float | None
    alt_setpoint_m: float | None
    _alt_mode_seen: bool
    rest_alt_m: float
    liftoff_seed: tuple[float, float] | None
    _liftoff: LiftoffDetector
    _lifted: bool

    def _go(self, state: SupervisorState, reason: str, level: Level = Level.INFO) -> None: ...
    def _note(self, level: Level, text: str) -> None: ...
    def _went(self, kind: OutcomeKind) -> None: ...
    def _send_every(self, period_s: float, *actions: Action) -> None: ...
    def _to_manual(self, reason: str, gate_us: int | None,
                   level: Level = Level.INFO) -> None: ...
    def _end_pc_control(self) -> None: ...


    def _climb_spool(self, inp: TickIn) -> RcCommand:
        """Motors spooling in STABILIZE or ALT_HOLD, stick at minimum; ALT_HOLD asked."""
        mode = inp.vehicle.mode
        if mode == FlightMode.ALT_HOLD:
            self._alt_mode_seen = True
        else:
            self.requested_mode, self._asked_why = FlightMode.ALT_HOLD, "for the climb-rate hold"
            self._send_every(self.p.mode_resend_s,
                             Action(ActionKind.SET_MODE, FlightMode.ALT_HOLD))
        spooled = self._t - self._armed_at_s >= self.p.spool_s
        if spooled and self._alt_mode_seen:
            assert self.climb is not None
            self.climb.engage(0.0)
            self._go(S.TAKEOFF, "motors spooled, in ALT_HOLD: climb rate asked until the "
                     "estimate climbs out of the rangefinder's blind band")
        elif spooled and self._t - max(self.since_s, self._armed_at_s + self.p.spool_s) > \
                MODE_WAIT_S:
            self._to_manual(f"take-off: the vehicle did not switch to ALT_HOLD within "
                            f"{MODE_WAIT_S:g} s", STICK_MIN_US, Level.ERROR)
            self._went(OutcomeKind.TAKEOFF_FAILED)
        return LEVEL_MIN

    def _climb_target(self) -> float:
        assert self.climb is not None
        p = self.climb.params
        return self.alt_target_m if self.alt_target_m is not None else p.blind_alt_m + p.band_m

    def _climb_takeoff(self, inp: TickIn) -> RcCommand:
        """The climb from the floor, open loop through the blind band."""
        climb = self.climb
        assert climb is not None
        if self._link is LinkHealth.DEGRADED:  # stale estimate: the firmware holds
            return LEVEL_MID
        est = inp.estimate
        target = self._climb_target()
        self.alt_setpoint_m = target
        # The firmware makes the climb, so nothing says what acceleration to expect; what the
        # accelerometer feels is the lift-off. From then on a reading under the minimum range
        # is the blind band, not the floor, and the estimate starts over from the climb felt
        # (pinned to the floor, the first readings past the band failed its gate).
        if not self._lifted and self._liftoff.update(est.acc_mps2, 0.0, inp.dt_s):
            self._lifted = True
            lo = self._liftoff
            self.liftoff_seed = (self.rest_alt_m + lo.rise_m, lo.vel_mps)
        if est.alt_m >= climb.params.blind_alt_m and est.vel_mps > 0.0:
            self._go(S.HOLD, f"climbed out of the rangefinder's blind band at {est.alt_m:.2f} m: "
                     "altitude hold on (climb rate)")
            self._went(OutcomeKind.LIFTED_OFF)
            return self._climb_hold(inp)
        if climb.blind_exhausted:
            self.requested_mode, self._asked_why = FlightMode.LAND, "asked: take-off not seen"
            self._send_every(self.p.mode_resend_s, Action(ActionKind.SET_MODE, FlightMode.LAND))
            self._end_pc_control()
            self._go(S.VEHICLE, f"take-off: {climb.open_loop_m:.2f} m of climb asked and the "
                     "estimate has not left the rangefinder's blind band: it is not the "
                     "vehicle's; LAND", Level.ERROR)
            self._went(OutcomeKind.TAKEOFF_FAILED)
            return LEVEL_MID
        self.climb_out = climb.update(target, est, inp.dt_s, self.alt_rate_mps, blind=True)
        return RcCommand(STICK_MID_US, STICK_MID_US, self.climb_out.throttle_us, STICK_MID_US)

    def _climb_hold(self, inp: TickIn) -> RcCommand:
        """The hold's climb rate toward the set point (sticks other than the throttle: the
        caller's)."""
        climb = self.climb
        assert climb is not None and self.alt_setpoint_m is not None
        est = inp.estimate
        blind = est.alt_m < climb.params.blind_alt_m
        self.climb_out = climb.update(self.alt_setpoint_m, est, inp.dt_s, self.alt_rate_mps,
                                      blind=blind and self.alt_setpoint_m > est.alt_m)
        return RcCommand(STICK_MID_US, STICK_MID_US, self.climb_out.throttle_us, STICK_MID_US)
