"""The take-off's own commands: the throttle ramp until the vehicle is felt to lift, and what
"above the sonar's blind band" means for the hold that takes over.

A part of `StateCommands` (gcs.supervisor.commands), which owns the state declared here.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from firmware_link.records import RcCommand
from gcs.control.altitude_controller import AltitudeController
from gcs.supervisor.liftoff import LiftoffDetector
from gcs.supervisor.outcomes import OutcomeKind
from gcs.supervisor.params import SupervisorParams
from gcs.supervisor.types import (
    STICK_MAX_US,
    STICK_MID_US,
    STICK_MIN_US,
    Level,
    LinkHealth,
    SupervisorState,
    TickIn,
)

S = SupervisorState
LEVEL = RcCommand(STICK_MID_US, STICK_MID_US, STICK_MIN_US, STICK_MID_US)


class TakeoffCommands:
    """The take-off ramp and the blind band's floor (state owned by `StateCommands`)."""

    p: SupervisorParams
    alt_ctrl: AltitudeController
    rest_alt_m: float
    hold_floor_m: float
    state: SupervisorState
    alt_target_m: float | None
    alt_setpoint_m: float | None
    liftoff_seed: tuple[float, float] | None
    _liftoff: LiftoffDetector
    _lifted: bool
    _link: LinkHealth
    _ramp_us: float
    _ramp_top_since_s: float | None
    _t: float

    if TYPE_CHECKING:  # what StateCommands provides
        def _engage(self, inp: TickIn, throttle_us: float, reason: str) -> None: ...
        def _hold(self, inp: TickIn) -> RcCommand: ...
        def _went(self, kind: OutcomeKind) -> None: ...
        def _to_manual(self, reason: str, gate_us: int | None,
                       level: Level = Level.INFO) -> None: ...

    @property
    def flies_above_blind(self) -> bool:
        """The PC holds a vehicle its take-off felt leave the floor, at or towards a height
        above the sonar's blind band: a reading below the minimum range is the blind band then,
        not the floor (the estimator's `airborne`); the climb-rate take-off's climb too, once
        felt. Not while it descends to land."""
        if self.state not in (S.HOLD, S.TAKEOFF) or not self._lifted:
            return False
        goal = self.alt_target_m if self.alt_target_m is not None else self.alt_setpoint_m
        return goal is not None and goal >= self.hold_floor_m

    def hold_target_m(self, setpoint_m: float) -> float:
        """A hold's altitude, raised to the blind band's top (plus its margin) when below."""
        return max(setpoint_m, self.hold_floor_m)

    def _takeoff(self, inp: TickIn) -> RcCommand:
        p = self.p
        est = inp.estimate
        hover = self.alt_ctrl.hover_stick_us()
        if self._ramp_us < 0.0:
            self._ramp_us = float(max(STICK_MIN_US, hover - p.ramp_below_hover_us))
        slow = self._ramp_us >= hover - p.ramp_slow_band_us
        rate = p.ramp_slow_rate_us_per_s if slow else p.ramp_rate_us_per_s
        if self._link is LinkHealth.DEGRADED:
            # stale telemetry: neither climb nor decide, and no more than hover: a vehicle
            # lifting unseen keeps its speed on it rather than gaining more
            held = min(round(self._ramp_us), max(hover, STICK_MIN_US))
            return RcCommand(STICK_MID_US, STICK_MID_US, held, STICK_MID_US)
        expected = self.alt_ctrl.accel_for_throttle(self._ramp_us, inp.roll_rad, inp.pitch_rad)
        felt = self._liftoff.update(est.acc_mps2, expected, inp.dt_s)
        seen = (est.alt_m > self.rest_alt_m + p.liftoff_rise_m
                and est.vel_mps > p.liftoff_vel_mps)
        if felt or seen:
            # Off the floor, the hover throttle holds it (no more ground effect to overcome);
            # the ramp's own value, accelerating the vehicle, would carry into an overshoot.
            # What it added while the lift-off was being recognised comes off.
            back = rate * p.liftoff_lag_s
            how = "seen by the sonar"
            self._lifted = True
            if felt:
                # the estimate stood on the floor (a blind sonar's zeros): it starts over
                # from the accelerometer's height and speed, the hold from there too
                lo = self._liftoff
                how = f"felt at {lo.rise_m * 100:.0f} cm, {lo.vel_mps:.2f} m/s"
                alt = self.rest_alt_m + lo.rise_m
                self.liftoff_seed = (alt, lo.vel_mps)
                inp = dataclasses.replace(inp, estimate=dataclasses.replace(
                    est, alt_m=alt, vel_mps=lo.vel_mps, control_alt_m=alt,
                    control_vel_mps=lo.vel_mps))
            self._engage(inp, max(STICK_MIN_US, min(hover, self._ramp_us - back)),
                         f"left the floor at {round(self._ramp_us)} us ({how}): altitude "
                         "hold on")
            self._went(OutcomeKind.LIFTED_OFF)
            return self._hold(inp)
        top = min(STICK_MAX_US, hover + p.ramp_above_hover_us)
        self._ramp_us = min(top, self._ramp_us + rate * inp.dt_s)
        if self._ramp_us >= top:
            self._ramp_top_since_s = self._ramp_top_since_s or self._t
            if self._t - self._ramp_top_since_s > p.takeoff_give_up_s:
                self._to_manual(f"take-off: the vehicle did not leave the floor at "
                                f"{top} us", STICK_MIN_US, Level.ERROR)
                self._went(OutcomeKind.TAKEOFF_FAILED)
                return LEVEL
        return RcCommand(STICK_MID_US, STICK_MID_US, round(self._ramp_us), STICK_MID_US)

