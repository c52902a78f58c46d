"""The one place that decides, every tick, which stick command and which messages are safe.

A pure state machine in the manner of PX4's failsafe framework: `step(TickIn)` takes the pilot's
intents, the vehicle's heartbeat state, how long the vehicle has been silent, the altitude
estimate and the attitude, and returns the override to send (or none), whether to send GCS
heartbeats, the command messages to send, and the reasons for every change of state. No clock,
no I/O: the station does the sending, `replay --rerun` feeds the recorded inputs back.

The rules, most severe first (see `params` for the link-loss policy):
- KILL wins in every state: throttle minimum from this tick, disarm (forced on 4.x) every
  `disarm_resend_s` until a heartbeat newer than the kill says disarmed — whatever the link says.
- A long silence lands a vehicle that may be flying; nothing undoes that when the link returns.
- A mode the station did not ask for, or a disarm, ends PC control; back in STABILIZE the
  throttle stays at minimum until the pilot's stick comes down to meet it.
- Take-off waits for the motors: throttle minimum through the spool-up, then an open-loop ramp
  that stops the moment the vehicle is seen to leave the floor; only then does the PID run.
- A steady hold asks no more down than the vehicle could fly blind until its failsafe
  (`envelope`): a radio fade then cannot put it on the floor faster than the bound.
"""

from __future__ import annotations

from firmware_link.records import FlightMode, RcCommand
from gcs.control.position_controller import PositionSetpoint
from gcs.supervisor.commands import LANDING_MODES, MANUAL_THROTTLE_MODES, S, StateCommands
from gcs.supervisor.outcomes import OutcomeKind
from gcs.supervisor.types import (
    AIRBORNE_CAPABLE,
    PC_CONTROL,
    STICK_MIN_US,
    Action,
    ActionKind,
    Intent,
    IntentKind,
    Level,
    LinkHealth,
    SupervisorOutput,
    TickIn,
    mode_name,
)


class Supervisor(StateCommands):
    """State machine around the altitude and position controllers (which it owns)."""

    # ------------------------------------------------------------------ the tick
    def step(self, inp: TickIn) -> SupervisorOutput:
        """Decide this tick's command and messages."""
        self._t = inp.t_s
        self._actions, self._notes, self._transitions = [], [], []
        self._outcomes = []
        for intent in inp.intents:
            self._apply(intent, inp)
        if inp.vehicle.seen:
            self._vehicle_mode = inp.vehicle.mode
        self._link = self.p.link_health(inp.vehicle.frame_age_s)
        self._watch_link(inp)
        if self._link is not LinkHealth.LOST:
            self._watch_vehicle(inp)
        command, heartbeat = self._run(inp)
        self._prev_alt_m = inp.estimate.alt_m
        if command is not None:
            self.command = command
        return SupervisorOutput(
            state=self.state, link=self._link, command=command, heartbeat=heartbeat,
            actions=tuple(self._actions), notes=tuple(self._notes),
            transitions=tuple(self._transitions), outcomes=tuple(self._outcomes),
            alt_setpoint_m=self.alt_setpoint_m if self.state in PC_CONTROL else None,
            throttle_gate_us=self.gate_us if self.state is S.MANUAL else None,
            command_acc_mps2=None if command is None or self.state is not S.HOLD
            or self.climb_out is not None else
            self.alt_ctrl.accel_for_throttle(command.throttle_us, inp.roll_rad, inp.pitch_rad))

    # ------------------------------------------------------------------ intents
    def _apply(self, it: Intent, inp: TickIn) -> None:
        k = it.kind
        if k is IntentKind.STICKS:
            self.sticks = RcCommand(it.roll_us, it.pitch_us, it.throttle_us, it.yaw_us)
        elif k is IntentKind.KILL:
            self._kill_at_s = self._t
            self._end_pc_control()
            self._go(S.KILLED, "KILL: throttle minimum, disarm until a heartbeat says disarmed",
                     Level.WARNING)
        elif k is IntentKind.PREFLIGHT:
            self.preflight_ok, self.preflight_note = it.ok, it.note
            self._note(Level.INFO if it.ok else Level.WARNING,
                       f"pre-flight {'passed' if it.ok else 'FAILED'}: {it.note}")
        elif self.state in (S.KILLED, S.RELEASED):
            self._ignored(k, f"{k.value} ignored: station is {self.state.value}")
        elif k is IntentKind.QUIT:
            self._quit(inp)
        elif self.state in (S.LINK_LOST, S.SILENT, S.QUITTING):
            self._ignored(k, f"{k.value} ignored while {self.state.value}")
        elif k is IntentKind.ARM:
            self._arm(it.wait_s)
        elif k is IntentKind.DISARM:
            self._actions.append(Action(ActionKind.DISARM))
            self._note(Level.INFO, "disarm requested")
        elif k is IntentKind.SET_MODE:
            self.requested_mode, self._asked_why = it.mode, "as asked"
            self._actions.append(Action(ActionKind.SET_MODE, it.mode))
            self._note(Level.INFO, f"mode {mode_name(it.mode)} requested")
        elif k is IntentKind.ALT_HOLD:
            self._alt_hold(it, inp)
        elif k is IntentKind.ALT_HOLD_OFF:
            if self.state in PC_CONTROL:
                self._end_pc_control()
                self._to_manual("altitude hold off: the pilot's throttle takes over where the "
                                "hold left it", self.command.throttle_us)
        elif k is IntentKind.POSITION:
            if self.pos_setpoint is None:
                self.pos_ctrl.reset()  # a new hold starts clean; a moved one keeps its state
            self.pos_setpoint = PositionSetpoint(it.north_m, it.east_m, it.yaw_rad)
        elif k is IntentKind.POSITION_OFF:
            self.pos_setpoint = None

    def _ignored(self, kind: IntentKind, text: str) -> None:
        if kind is IntentKind.ARM:
            self._ended(OutcomeKind.ARM_IGNORED, Level.WARNING, text)
        elif kind is IntentKind.ALT_HOLD:
            self._ended(OutcomeKind.ALT_HOLD_REFUSED, Level.WARNING, text)
        else:
            self._note(Level.WARNING, text)

    def _arm(self, wait_s: float | None) -> None:
        self.arm_wait_s = self.p.arm_timeout_s if wait_s is None else wait_s
        if self.state is not S.DISARMED:
            self._ended(OutcomeKind.ARM_IGNORED, Level.WARNING,
                        f"arm ignored: already {self.state.value}")
        elif not self.preflight_ok:
            self._ended(OutcomeKind.ARM_REFUSED, Level.ERROR, f"arm refused: {self.preflight_note}")
        else:
            self._go(S.ARMING, "arm requested")

    def _alt_hold(self, it: Intent, inp: TickIn) -> None:
        if self.state in (S.DISARMED, S.ARMING, S.VEHICLE):
            why = ("arm first" if self.state is not S.VEHICLE else
                   f"the vehicle flies itself in {mode_name(inp.vehicle.mode)}; "
                   "switch to STABILIZE first")
            if self.state is S.ARMING:
                if not self._takeoff_wanted:
                    self._takeoff_asked_s = self._t
                    self._note(Level.INFO, f"take-off waits up to {self.p.takeoff_wait_s:g} s "
                               "for the arm")
                self._takeoff_wanted = True
                target, rate = it.setpoint_m, it.rate_mps
                if target is None:
                    target = self.takeoff_alt_m
                    rate = self.takeoff_climb_mps if rate is None else rate
                self.alt_target_m, self.alt_rate_mps = self.hold_target_m(target), rate
                return
            self._ended(OutcomeKind.ALT_HOLD_REFUSED, Level.WARNING,
                        f"altitude hold refused: {why}")
            return
        if inp.vehicle.seen and not inp.vehicle.armed:
            # The heartbeat saying so may come before the tick that leaves MANUAL for DISARMED
            # (intents are applied first): a take-off ramp on a disarmed vehicle winds up.
            self._ended(OutcomeKind.ALT_HOLD_REFUSED, Level.WARNING,
                        "altitude hold refused: the vehicle is disarmed")
            return
        if inp.vehicle.mode not in (FlightMode.STABILIZE, self.pc_mode):
            self._ended(OutcomeKind.ALT_HOLD_REFUSED, Level.WARNING, "altitude hold refused: the "
                        f"PC flies in {mode_name(self.pc_mode)} (from STABILIZE), the vehicle is "
                        f"in {mode_name(inp.vehicle.mode)}")
            return
        target, rate = it.setpoint_m, it.rate_mps
        from_floor = self.state is S.MANUAL and self.on_floor(inp.estimate.alt_m)
        if from_floor or self.state in (S.SPOOL_UP, S.TAKEOFF):
            # A hold asked on the floor is a take-off: to the take-off altitude when it names
            # none (the lift-off height was 0.10 m, in the sonar's blind band), never into the
            # band. The band's top holds in the air too; a descent (fly's landing) may go lower.
            if target is None:
                target = self.takeoff_alt_m
                rate = self.takeoff_climb_mps if rate is None else rate
            target = self.hold_target_m(target)
        elif target is None and self.state is S.MANUAL:
            target = (self.hold_target_m(inp.estimate.alt_m)
                      if inp.estimate.alt_m < self.hold_floor_m else None)
        self.alt_target_m, self.alt_rate_mps = target, rate
        if self.state is S.MANUAL:
            if from_floor:
                self._go(S.SPOOL_UP if self._t - self._armed_at_s < self.p.spool_s
                         else S.TAKEOFF, f"take-off asked, to {target:.2f} m")
            else:
                self._engage(inp, self.command.throttle_us, "altitude hold on")

    def _quit(self, inp: TickIn) -> None:
        v = inp.vehicle
        if self.state in (S.DISARMED, S.ARMING) or (v.seen and not v.armed):
            self._release("quit: vehicle disarmed")
        elif self.state in (S.SILENT, S.LINK_LOST):
            self._note(Level.WARNING, f"quit while {self.state.value}: the vehicle's own "
                       "failsafe lands it")
        elif self.state is not S.QUITTING:  # asked again (each second) while it lands
            self._in_land_s = None
            self._go(S.QUITTING, "quit while armed: LAND first, then release once disarmed",
                     Level.WARNING)

    def _release(self, reason: str) -> None:
        self._end_pc_control()
        self._actions.append(Action(ActionKind.RELEASE))
        self._go(S.RELEASED, reason)

    # ------------------------------------------------------------------ observations
    def _watch_link(self, inp: TickIn) -> None:
        if self._link is not LinkHealth.LOST or self.state not in AIRBORNE_CAPABLE:
            return
        self._lost_at_s = self._t
        self._lost_throttle_us = self.safe_throttle_us(inp.estimate.alt_m)
        self._lost_height_m = inp.estimate.alt_m - self.rest_alt_m
        self._lost_down = False
        self._end_pc_control()
        self._go(S.LINK_LOST, f"nothing heard from the vehicle for "
                 f"{inp.vehicle.frame_age_s:.1f} s: commanding LAND", Level.ERROR)

    def _watch_vehicle(self, inp: TickIn) -> None:
        v = inp.vehicle
        if not v.seen:
            return
        st = self.state
        if st is S.KILLED:
            if not v.armed and v.heartbeat_t_s >= self._kill_at_s:
                self._go(S.DISARMED, "disarmed after kill")
            return
        if st is S.SILENT:
            self._go(S.LINK_LOST, "the vehicle is heard again: heartbeats back on, the landing "
                     "stands", Level.WARNING)
            st = self.state
        if not v.armed:
            if st is S.QUITTING:
                self._release("vehicle disarmed")
            elif st in AIRBORNE_CAPABLE - {S.ARMING} or st is S.LINK_LOST:
                self._end_pc_control()
                self._go(S.DISARMED, "vehicle disarmed", Level.WARNING)
            return
        if st is S.DISARMED:
            self._armed_at_s = self._t
            self._to_manual("vehicle armed (not by this station)", STICK_MIN_US, Level.WARNING)
        elif st is S.ARMING:
            self._armed_at_s = self._t
            if self._takeoff_wanted:
                self._go(S.SPOOL_UP, "armed: waiting for the motors to spool up")
            else:
                self._to_manual("armed", STICK_MIN_US)
            self._went(OutcomeKind.ARMED)
        elif st is S.QUITTING:
            if v.mode == FlightMode.LAND and self._in_land_s is None:
                self._in_land_s = self._t
                self._disarm_report_s = self._t + self.p.disarm_report_s
                self._note(Level.INFO, "quit: vehicle in LAND: throttle minimum and heartbeats "
                           "until it disarms, then overrides released")
        elif st is S.LINK_LOST:
            if v.mode == FlightMode.LAND:
                self._go(S.VEHICLE, "the vehicle is heard again and lands in LAND")
        else:
            self._watch_mode(v.mode)

    def _watch_mode(self, mode: int) -> None:
        asked = self.requested_mode == mode
        how = self._asked_why if asked else "by itself"
        st = self.state
        if st in PC_CONTROL:
            if self.climb is not None and mode == FlightMode.ALT_HOLD:
                self._alt_mode_seen = True
            # climb-rate: STABILIZE until ALT_HOLD shows (the station asked for it)
            flies = mode == self.pc_mode or (mode == FlightMode.STABILIZE
                                             and not self._alt_mode_seen)
            if not flies:
                self._end_pc_control()
                self._go(S.VEHICLE, f"vehicle in {mode_name(mode)} {how}: PC control off",
                         Level.INFO if asked else Level.WARNING)
        elif st is S.MANUAL:
            if mode in LANDING_MODES or (not asked and mode not in MANUAL_THROTTLE_MODES
                                         and self.requested_mode is not None):
                self._go(S.VEHICLE, f"vehicle in {mode_name(mode)} {how}",
                         Level.INFO if asked else Level.WARNING)
        elif st is S.VEHICLE:
            if mode in MANUAL_THROTTLE_MODES:
                self._to_manual(f"vehicle in {mode_name(mode)} {how}: throttle held at minimum "
                                "until the pilot's stick comes down to it", STICK_MIN_US)
            elif asked and mode not in LANDING_MODES:
                self._to_manual(f"vehicle in {mode_name(mode)} as asked", None)
