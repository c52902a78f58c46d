"""The supervisor's state, its bookkeeping, and the command each state sends.

`Supervisor` (gcs.supervisor.supervisor) adds the tick, the intents and the observations that
move it from state to state; what a state then sends (the take-off ramp, the altitude and
position hold, the link-loss throttle, the repeated disarm of a kill) is here.
"""

from __future__ import annotations

import math

from firmware_link.records import FlightMode, RcCommand
from gcs.control.altitude_controller import AltControlOutput, AltitudeController
from gcs.control.climb_rate_hold import ClimbRateHold, ClimbRateOutput
from gcs.control.position_controller import PositionCommand, PositionController, PositionSetpoint
from gcs.estimation import SonarStatus
from gcs.supervisor.climb_mode import ClimbModeCommands, pc_mode
from gcs.supervisor.envelope import blind_sink_limit
from gcs.supervisor.liftoff import LiftoffDetector
from gcs.supervisor.outcomes import Outcome, OutcomeKind
from gcs.supervisor.params import SupervisorParams
from gcs.supervisor.takeoff import TakeoffCommands
from gcs.supervisor.types import (
    STICK_MID_US,
    STICK_MIN_US,
    Action,
    ActionKind,
    Level,
    LinkHealth,
    Note,
    SupervisorState,
    TickIn,
    Transition,
)

S = SupervisorState
MOCAP_STALE_S = 0.25
LANDING_MODES = frozenset({FlightMode.LAND, FlightMode.RTL, FlightMode.AUTO, FlightMode.GUIDED})
"""Modes that ignore the throttle stick (or use it only to disarm): send it at minimum."""
MANUAL_THROTTLE_MODES = frozenset({FlightMode.STABILIZE, FlightMode.ACRO})
LEVEL = RcCommand(STICK_MID_US, STICK_MID_US, STICK_MIN_US, STICK_MID_US)


class StateCommands(ClimbModeCommands, TakeoffCommands):
    """The state the supervisor keeps and the commands its states send."""

    def __init__(self, params: SupervisorParams, alt_ctrl: AltitudeController,
                 pos_ctrl: PositionController, *, rest_alt_m: float, ground_alt_m: float,
                 hold_floor_m: float = 0.0, takeoff_alt_m: float = 1.0,
                 takeoff_climb_mps: float | None = None,
                 climb: ClimbRateHold | None = None) -> None:
        """`hold_floor_m`: the lowest altitude a hold is asked to keep (the sonar's blind band
        plus a margin); `takeoff_alt_m`, `takeoff_climb_mps`: where a hold asked on the floor
        with no altitude of its own climbs to, how fast (None: the controller's profile);
        `climb`: the climb-rate hold, flown in ALT_HOLD (None: the direct-throttle hold)."""
        self.p = params
        self.alt_ctrl = alt_ctrl
        # the climb-rate hold, flown in ALT_HOLD (climb_mode); None: the direct-throttle hold
        self.climb = climb
        self.climb_out: ClimbRateOutput | None = None
        self.pc_mode = pc_mode(climb)
        self._alt_mode_seen = False  # climb-rate: ALT_HOLD shown since PC control began
        self._vehicle_mode = -1  # the last heartbeat's mode
        self.pos_ctrl = pos_ctrl
        self.rest_alt_m = rest_alt_m
        self.ground_alt_m = ground_alt_m
        self.hold_floor_m = hold_floor_m
        self.takeoff_alt_m = max(takeoff_alt_m, hold_floor_m)
        self.takeoff_climb_mps = takeoff_climb_mps
        self._liftoff = LiftoffDetector()
        self._lifted = False  # the take-off felt the vehicle leave the floor; PC control since
        # (altitude m, velocity m/s) where it was felt to, for the estimator's next tick
        self.liftoff_seed: tuple[float, float] | None = None
        self._blind = params.blind(alt_ctrl.params.gains.out_max)
        self.state = S.DISARMED
        self.since_s = 0.0
        self.sticks = RcCommand()
        self.command = LEVEL
        self.requested_mode: int | None = None
        self._asked_why = "as asked"  # why the station asked for requested_mode
        self.preflight_ok = False
        self.preflight_note = "pre-flight checks not run"
        self.alt_target_m: float | None = None
        self.alt_rate_mps: float | None = None
        self.alt_setpoint_m: float | None = None
        self.pos_setpoint: PositionSetpoint | None = None
        self.alt: AltControlOutput | None = None
        self.position: PositionCommand | None = None
        self.gate_us: int | None = None
        self._gate_side = 0
        self._takeoff_wanted = False
        self._armed_at_s = -math.inf
        self._kill_at_s = -math.inf
        self._lost_at_s = -math.inf
        self._lost_throttle_us = STICK_MIN_US  # chosen when the link was lost, held through it
        self._lost_height_m = 0.0  # above the rest height when the link was lost
        self._lost_down = False  # a LAND asked on the lost link has had time to touch down
        self._takeoff_asked_s = -math.inf  # a take-off asked while arming, waiting for the arm
        self.arm_wait_s = params.arm_timeout_s  # how long the arm asked now is asked again
        self._in_land_s: float | None = None  # quitting: when a heartbeat first showed LAND
        self._disarm_report_s = math.inf  # quitting: when the next "still armed" is due
        self._next_send_s = -math.inf
        self._ramp_us = 0.0
        self._ramp_top_since_s: float | None = None
        self._frozen: RcCommand | None = None
        self._prev_alt_m: float | None = None  # last tick's altitude estimate
        self._mocap_ok = False
        self._link = LinkHealth.OK
        self._actions: list[Action] = []
        self._notes: list[Note] = []
        self._transitions: list[Transition] = []
        self._outcomes: list[Outcome] = []
        self._t = 0.0

    # ------------------------------------------------------------------ bookkeeping
    def _go(self, state: SupervisorState, reason: str, level: Level = Level.INFO) -> None:
        if state is self.state:
            return
        self._transitions.append(Transition(self._t, self.state, state, reason))
        self._notes.append(Note(level, f"{state.value}: {reason}"))
        self.state = state
        self.since_s = self._t
        self._next_send_s = -math.inf  # a new state's first message goes out at once
        if state is S.TAKEOFF:
            self._ramp_us = -1.0  # set from the hover stick on the first take-off tick
            self._ramp_top_since_s = None
            self._liftoff.reset()
        if state not in (S.HOLD, S.LINK_LOST, S.QUITTING):
            self._lifted = False

    def _note(self, level: Level, text: str) -> None:
        self._notes.append(Note(level, text))

    def _ended(self, kind: OutcomeKind, level: Level, text: str) -> None:
        """A request's end: its note for the pilot, its outcome for the caller."""
        self._note(level, text)
        self._outcomes.append(Outcome(kind, self._t, text))

    def _went(self, kind: OutcomeKind) -> None:
        """A request's end told by the transition just made, with that transition's note."""
        tr = self._transitions[-1]
        self._outcomes.append(Outcome(kind, self._t, f"{tr.state.value}: {tr.reason}"))

    def _send_every(self, period_s: float, *actions: Action) -> None:
        if self._t >= self._next_send_s:
            self._actions.extend(actions)
            self._next_send_s = self._t + period_s

    def _to_manual(self, reason: str, gate_us: int | None, level: Level = Level.INFO) -> None:
        """Hand the sticks to the pilot; the throttle waits at `gate_us` until the stick meets
        it."""
        self.gate_us = gate_us
        if gate_us is not None:
            thr = self.sticks.throttle_us
            self._gate_side = (thr > gate_us) - (thr < gate_us)
        self.alt = None
        self.position = None
        self._takeoff_wanted = False
        self._go(S.MANUAL, reason, level)

    def _end_pc_control(self) -> None:
        self.alt = None
        self.climb_out = None
        self._alt_mode_seen = False
        self.position = None
        self.alt_setpoint_m = None
        self._takeoff_wanted = False

    @property
    def waits_for_disarm(self) -> bool:
        """Quitting with LAND shown: the station stays (throttle minimum, heartbeats) until a
        heartbeat shows the vehicle disarmed, however long that takes."""
        return self.state is S.QUITTING and self._in_land_s is not None

    def on_floor(self, alt_m: float) -> bool:
        """Whether an altitude estimate means standing on the floor."""
        return alt_m < self.ground_alt_m

    # ------------------------------------------------------------------ commands per state
    def _run(self, inp: TickIn) -> tuple[RcCommand | None, bool]:
        st = self.state
        if st is S.KILLED:
            disarm = Action(ActionKind.FORCE_DISARM if self.p.force_disarm else ActionKind.DISARM)
            acts = [disarm]
            if ((self.p.stabilize_to_disarm or self.climb is not None)
                    and inp.vehicle.mode not in MANUAL_THROTTLE_MODES):
                acts.insert(0, Action(ActionKind.SET_MODE, FlightMode.STABILIZE))
            self._send_every(self.p.disarm_resend_s, *acts)
            return LEVEL, True
        if st in (S.DISARMED, S.RELEASED):
            return (None if st is S.RELEASED else LEVEL), True
        if st is S.ARMING:
            if self._takeoff_wanted and self._t - self._takeoff_asked_s > self.p.takeoff_wait_s:
                self._takeoff_wanted = False  # asked of an armed vehicle, not of a later one
                self._ended(OutcomeKind.ALT_HOLD_REFUSED, Level.WARNING,
                            f"take-off expired: the vehicle did not arm within "
                            f"{self.p.takeoff_wait_s:g} s of it; ask again once armed")
            if self._t - self.since_s > self.arm_wait_s:
                self._takeoff_wanted = False
                self._go(S.DISARMED, f"vehicle did not arm within {self.arm_wait_s:g} s: the arm "
                         "request has expired, ask again", Level.ERROR)
                self._went(OutcomeKind.ARM_TIMED_OUT)
            else:
                self._send_every(self.p.arm_resend_s, Action(ActionKind.ARM))
            return LEVEL, True
        if st is S.LINK_LOST:
            # LAND asked until the vehicle is heard again, heartbeats on (params: the policy)
            self._send_every(self.p.mode_resend_s, Action(ActionKind.SET_MODE, FlightMode.LAND))
            p = self.p
            down_s = (p.land_request_s + max(self._lost_height_m, 0.0) / p.land_speed_mps
                      + p.landed_settle_s)
            if (not self._lost_down and self._t - self._lost_at_s >= down_s
                    and self._link is LinkHealth.LOST):
                self._lost_down = True
                self._note(Level.ERROR, f"still nothing heard {self._t - self._lost_at_s:.1f} s "
                           "after LAND was first asked: it has touched down by now (ours or its "
                           "failsafe's); throttle minimum so it disarms, heartbeats on until a "
                           "heartbeat shows it disarmed")
            if self._lost_down and (self._link is LinkHealth.LOST
                                    or inp.vehicle.mode in LANDING_MODES):
                return LEVEL, True
            return self._safe_hold(self._lost_throttle_us), True
        if st is S.SILENT:
            return None, False
        if st is S.VEHICLE:
            thr = STICK_MIN_US if inp.vehicle.mode in LANDING_MODES else STICK_MID_US
            return RcCommand(STICK_MID_US, STICK_MID_US, thr, STICK_MID_US), True
        if st is S.QUITTING:
            if self._in_land_s is not None:
                return self._stay_until_disarmed(inp), True
            if self._t - self.since_s > self.p.quit_timeout_s:
                self._note(Level.ERROR, "quit: LAND not confirmed in time")
            self._send_every(self.p.mode_resend_s, Action(ActionKind.SET_MODE, FlightMode.LAND))
            holding = self.alt is not None or self.climb_out is not None
            return (self._hold(inp) if holding else self._manual()), True
        if st is S.MANUAL:
            return self._manual(), True
        if st is S.SPOOL_UP and self.climb is not None:
            return self._climb_spool(inp), True
        if st is S.TAKEOFF and self.climb is not None:
            return self._climb_takeoff(inp), True
        if st is S.SPOOL_UP:
            if self._t - self._armed_at_s >= self.p.spool_s:
                self._go(S.TAKEOFF, "motors spooled: throttle ramp until the vehicle lifts")
            return LEVEL, True
        if st is S.TAKEOFF:
            return self._takeoff(inp), True
        return self._hold(inp), True

    def _stay_until_disarmed(self, inp: TickIn) -> RcCommand:
        """A quitting station whose LAND has shown: throttle minimum (LAND ignores the stick in
        the air; 3.2.1 disarms after it only with the stick at minimum), level, heartbeats on,
        until a heartbeat shows the vehicle disarmed (the supervisor then releases). Going quiet
        on it instead lets 3.2.1's GCS failsafe RTL the landed vehicle back up (measured)."""
        assert self._in_land_s is not None
        if inp.vehicle.mode != FlightMode.LAND:  # moved on (a failsafe's RTL): LAND again
            self._send_every(self.p.mode_resend_s, Action(ActionKind.SET_MODE, FlightMode.LAND))
        if self._t >= self._disarm_report_s:
            self._disarm_report_s = self._t + self.p.disarm_report_s
            self._note(Level.ERROR, f"quit: still armed {self._t - self._in_land_s:.0f} s after "
                       "LAND showed: throttle minimum and heartbeats go on until it disarms "
                       "(disarm it by hand, or kill)")
        if inp.vehicle.mode not in LANDING_MODES:
            return self._safe_hold(self.safe_throttle_us(inp.estimate.alt_m))
        return LEVEL

    def safe_throttle_us(self, alt_m: float) -> int:
        """The throttle for a vehicle that cannot be heard (or a loop that died): hover where it
        flies (the hover the hold has learned, with its integrator's trim: the throttle it
        actually holds at, not an assumed one), so it neither climbs nor falls; minimum on the
        floor, where hover throttle would lift it (3.2.1's THR_MID is 1500 us); never above the
        pilot's own stick in MANUAL."""
        if self.on_floor(alt_m) and not self._lifted:
            return STICK_MIN_US
        # (a vehicle felt to lift is not on the floor, whatever an estimate still in the blind
        # band says: minimum there drops it from up to the band's top, 2 m/s from 0.25 m)
        if self.climb is not None and self._vehicle_mode == FlightMode.ALT_HOLD:
            return STICK_MID_US  # ALT_HOLD's dead zone: the firmware holds its height
        hover = self.alt_ctrl.flown_hover_stick_us()
        if self.state is S.MANUAL:
            return min(hover, self.sticks.throttle_us if self.gate_us is None else self.gate_us)
        return hover

    @staticmethod
    def _safe_hold(throttle_us: int) -> RcCommand:
        """Level, no yaw: no chase."""
        return RcCommand(STICK_MID_US, STICK_MID_US, throttle_us, STICK_MID_US)

    def _manual(self) -> RcCommand:
        s = self.sticks
        if self.gate_us is not None:
            side = (s.throttle_us > self.gate_us) - (s.throttle_us < self.gate_us)
            near = abs(s.throttle_us - self.gate_us) <= self.p.pickup_band_us
            if near or side != self._gate_side:
                self.gate_us = None
                self._note(Level.INFO, "the pilot's throttle has the vehicle")
            else:
                return RcCommand(s.roll_us, s.pitch_us, self.gate_us, s.yaw_us)
        return s

    # ------------------------------------------------------------------ PC control
    def _engage(self, inp: TickIn, throttle_us: float, reason: str) -> None:
        self.alt_ctrl.engage(inp.estimate, throttle_us, inp.roll_rad, inp.pitch_rad)
        if self.climb is not None:
            self.climb.engage(0.0)
        self.alt_setpoint_m = inp.estimate.alt_m
        self._frozen = None
        self._go(S.HOLD, reason)

    def _hold(self, inp: TickIn) -> RcCommand:
        if self._link is LinkHealth.DEGRADED:
            if self._frozen is None:
                self._frozen = self._safe_hold(self.safe_throttle_us(inp.estimate.alt_m))
                self._note(Level.WARNING, f"telemetry gap: throttle held at "
                           f"{self._frozen.throttle_us} us, level")
            return self._frozen
        if self._frozen is not None:
            self._frozen = None
            self._note(Level.INFO, "telemetry back: altitude hold resumes")
        est = inp.estimate
        assert self.alt_setpoint_m is not None
        if est.sonar_status is SonarStatus.REACQUIRED and self._prev_alt_m is not None:
            # The estimator re-based on another surface (past a table's edge, or back from a
            # drift), not a move: held as it comes, the vehicle dives for the table it left. As
            # ArduCopter's surface tracking does, the hold keeps its height over the new one.
            jump = est.alt_m - self._prev_alt_m
            self.alt_ctrl.surface_changed(jump)
            self.alt_setpoint_m += jump
            if self.alt_target_m is not None:
                self.alt_target_m += jump
        elif est.sonar_status is SonarStatus.UNBLINDED and self._prev_alt_m is not None:
            # The sonar's first word after the blind band corrected the accelerometer's coast
            # through it: the climb goes on from where the vehicle is, at the profile's pace,
            # to the same target, rather than surging to catch up a profile that ran ahead
            # of it by the coast's drift (8-9 cm: lockstep copter4 seed 2 overshot 5 %).
            self.alt_ctrl.surface_changed(est.alt_m - self._prev_alt_m)
        # the controller's profile makes the move: a ramp stopping dead would overshoot
        if self.alt_target_m is not None:
            self.alt_setpoint_m = self.alt_target_m
        if self.climb is not None:
            if inp.vehicle.mode == FlightMode.ALT_HOLD:
                self._alt_mode_seen = True
            if self._alt_mode_seen:
                return self._with_position(inp, self._climb_hold(inp))
            # engaged in the air from STABILIZE: ALT_HOLD asked, the direct hold flies until
            # a heartbeat shows it (a mid-stick in STABILIZE would be no hover)
            self.requested_mode, self._asked_why = FlightMode.ALT_HOLD, "for the climb-rate hold"
            self._send_every(self.p.mode_resend_s, Action(ActionKind.SET_MODE, FlightMode.ALT_HOLD))
        floor = self.on_floor(est.alt_m) and self.alt_setpoint_m <= est.alt_m
        sink = blind_sink_limit(est.alt_m - self.rest_alt_m, est.vel_mps,
                                est.alt_m - self.alt_setpoint_m, self._blind)
        self.alt = self.alt_ctrl.update(self.alt_setpoint_m, est, inp.roll_rad, inp.pitch_rad,
                                        inp.dt_s, on_floor=floor, rate_mps=self.alt_rate_mps,
                                        sink_limit_mps2=sink)
        blocked = self.alt_ctrl.blocked_climb_s
        if blocked >= self.p.blocked_climb_s and self.state is S.HOLD:
            if blocked - inp.dt_s < self.p.blocked_climb_s:
                self._note(Level.ERROR, f"full climb asked for {blocked:.1f} s and the estimate "
                           "did not rise: the estimate is not the vehicle's, or thrust is "
                           "lost: LAND")
            self.requested_mode, self._asked_why = FlightMode.LAND, "asked: no rise at full climb"
            self._send_every(self.p.mode_resend_s, Action(ActionKind.SET_MODE, FlightMode.LAND))
        return self._with_position(inp, RcCommand(STICK_MID_US, STICK_MID_US,
                                                  self.alt.throttle_us, STICK_MID_US))

    def _with_position(self, inp: TickIn, hold: RcCommand) -> RcCommand:
        """The hold's throttle with the pilot's sticks, or the mocap position hold's."""
        roll, pitch, yaw = self.sticks.roll_us, self.sticks.pitch_us, self.sticks.yaw_us
        self.position = None
        if self.pos_setpoint is not None:
            pose = inp.mocap
            fresh = pose is not None and inp.t_s - pose.t_s <= MOCAP_STALE_S
            if fresh and pose is not None:
                self.position = self.pos_ctrl.update(self.pos_setpoint, pose, inp.dt_s,
                                                     (inp.roll_rad, inp.pitch_rad))
                roll, pitch, yaw = (self.position.roll_us, self.position.pitch_us,
                                    self.position.yaw_us)
            else:
                roll, pitch, yaw = STICK_MID_US, STICK_MID_US, STICK_MID_US
            if fresh != self._mocap_ok:
                self._note(Level.INFO if fresh else Level.WARNING,
                           "motion capture " + ("tracking" if fresh else "lost: holding level"))
                self._mocap_ok = fresh
        return RcCommand(roll, pitch, hold.throttle_us, yaw)
