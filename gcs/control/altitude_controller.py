"""Altitude controller per the thesis's Fig. 6.2, on an ArduCopter throttle stick.

The PID acts on the altitude error and outputs a vertical acceleration (K_P in s⁻², K_I in s⁻³,
K_D in s⁻¹, as the figure's units say); the thrust is U = m·(g + PID)/(cos φ·cos θ). The thesis
then scales the output to 1000..2000 directly; here U is mapped to a motor throttle through the
hover throttle (thrust ∝ throttle, hover ⇔ m·g) and to a stick PWM through the inverse of the
firmware's manual throttle curve. The derivative uses the estimator's velocity (the derivative of
the measurement, no kick). The hover throttle is learned slowly in steady hover, as ArduCopter
learns MOT_THST_HOVER (10 s time constant).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from gcs.control.pid import Pid, PidGains, PidTerms
from gcs.control.throttle_curve import ThrottleCurve
from gcs.estimation import GRAVITY_MPS2, AltEstimate


def _default_alt_gains() -> PidGains:
    return PidGains(
        # closed-loop poles of s³ + kd·s² + kp·s + ki at -0.65 and 2.5 rad/s with damping 0.88,
        # slow enough for the ~100 ms of link, attitude and motor lag. On the hold's own filter
        # (gcs/estimation/control.py) the stiffer 12, 6, 5.5 only amplified sonar noise: 60
        # seeds a profile (apm25 / copter4), lockstep, control filter at 4 m/s²: std median
        # 1.02 / 0.86 cm, against 0.95 / 0.75 cm with these at 8 m/s² (at the 2 m/s² it flies
        # with, for a calmer throttle: 1.18 / 0.96 cm)
        kp=9.0,  # s⁻²
        ki=4.0,  # s⁻³
        kd=5.0,  # s⁻¹
        i_max=3.0,  # m/s² of trim the integrator may hold
        out_min=-6.0,
        out_max=6.0,
        d_filter_hz=8.0,
        setpoint_slew_per_s=1.0,
        setpoint_accel_per_s2=1.5,
        ff_accel=1.0,  # the output is an acceleration: the profile's own goes straight through
        # P then asks at most 2.7 m/s², and against kd the loop closes a larger error at about
        # kp·leash/kd ≈ 0.54 m/s: a jump of the estimate (a carpet echo believed late, a sonar
        # reacquisition) cannot throw the vehicle at the floor or the ceiling
        error_max=0.3,
    )


@dataclass(frozen=True, slots=True)
class AltitudeControllerParams:
    """Tuning of the altitude loop. Mass from thesis ch. 7 (1.63 kg)."""

    mass_kg: float = 1.63
    gains: PidGains = field(default_factory=_default_alt_gains)
    max_tilt_rad: float = math.radians(45.0)  # beyond this the cosine compensation stops growing
    hover_learn_tc_s: float = 10.0
    # what a throttle held blind uses (`flown_hover`): the steady hover's level throttle over
    # ~2 s; apm25 lockstep hold, seed 1: within 4 us of the mean command with 1 s (its noise),
    # the 10 s learner 5 us under it (they start close there; on the real 3.2.1, 69 us apart)
    flown_hover_tc_s: float = 2.0
    hover_learn_max_vel_mps: float = 0.2
    hover_learn_max_err_m: float = 0.1
    # All the climb the loop may ask (the output or the stick at its top, or P at its leash
    # with the integrator this near its limit), yet rising slower than this: blocked
    blocked_climb_i_share: float = 0.9
    blocked_climb_vel_mps: float = 0.1
    hover_min: float = 0.15
    hover_max: float = 0.8
    throttle_min_us: int = 1000
    throttle_max_us: int = 2000

    def __post_init__(self) -> None:
        if self.mass_kg <= 0.0 or self.hover_learn_tc_s <= 0.0 or self.flown_hover_tc_s <= 0.0:
            raise ValueError("mass_kg, hover_learn_tc_s and flown_hover_tc_s must be > 0")
        if not 0.0 < self.hover_min < self.hover_max < 1.0:
            raise ValueError("need 0 < hover_min < hover_max < 1")


@dataclass(frozen=True, slots=True)
class AltControlOutput:
    """One step of the altitude loop: the PID terms and what became of them."""

    setpoint_m: float
    alt_m: float
    error_m: float
    p: float
    i: float
    d: float
    accel_cmd_mps2: float
    thrust_n: float
    motor_throttle: float  # 0..1
    hover_throttle: float  # learned, 0..1
    throttle_us: int
    saturated: bool


class AltitudeController:
    """Altitude PID → thrust → motor throttle → throttle stick PWM."""

    def __init__(self, params: AltitudeControllerParams, curve: ThrottleCurve,
                 hover_throttle: float | None = None) -> None:
        self.params = params
        self.curve = curve
        self.pid = Pid(params.gains)
        h = curve.mid_output if hover_throttle is None else hover_throttle
        self.hover_throttle = min(max(h, params.hover_min), params.hover_max)
        # the level throttle of the steady hover seen last, learned faster than hover_throttle
        self.flown_hover = self.hover_throttle
        # which way the last stick command was clamped (+1 at the top, -1 at the bottom): the
        # integrator must not keep growing into a stick that cannot move further
        self._clamped = 0
        # how long the loop has asked for all the climb it may while the estimate did not rise
        # (see SupervisorParams.blocked_climb_s)
        self.blocked_climb_s = 0.0

    def _tilt(self, roll_rad: float, pitch_rad: float) -> float:
        c = math.cos(roll_rad) * math.cos(pitch_rad)
        return max(c, math.cos(self.params.max_tilt_rad))

    def accel_for_throttle(self, throttle_us: float, roll_rad: float, pitch_rad: float) -> float:
        """The vertical acceleration command a stick PWM stands for (used for bumpless engage)."""
        out = self.curve.output(throttle_us) * self._tilt(roll_rad, pitch_rad)
        return GRAVITY_MPS2 * (out / self.hover_throttle - 1.0)

    def engage(self, estimate: AltEstimate, throttle_us: float | None,
               roll_rad: float = 0.0, pitch_rad: float = 0.0) -> None:
        """Take over from a pilot's stick without a jump (None: start from hover, I = 0)."""
        a0 = 0.0
        if throttle_us is not None:
            a0 = self.accel_for_throttle(throttle_us, roll_rad, pitch_rad)
        alt = _flown_alt(estimate)
        self.pid.engage(alt, alt, a0)
        self._clamped = 0
        self.blocked_climb_s = 0.0

    def surface_changed(self, jump_m: float) -> None:
        """The estimate jumped by `jump_m` because the sonar now measures from another surface
        (a table top, the floor past its edge): the setpoint profile jumps with it, so that
        neither the error nor the derivative steps (the caller moves the target too)."""
        self.pid.shift_setpoint(jump_m)

    def hover_stick_us(self) -> int:
        """The stick PWM that holds the learned hover throttle, level."""
        p = self.params
        stick = self.curve.stick_us(self.hover_throttle)
        return round(min(max(stick, p.throttle_min_us), p.throttle_max_us))

    def flown_hover_stick_us(self) -> int:
        """The stick PWM the vehicle was last seen hovering on, level (`flown_hover`): what a
        throttle held blind must be. The learned hover trails it with a 10 s time constant (a
        hold started from 3.2.1's THR_MID still had 1439 us of "hover" against the vehicle's real
        1370 us, and the throttle held blind on it climbed), and the integrator is no trim right
        after an engage (it holds the pilot's stick then, bumpless)."""
        p = self.params
        stick = self.curve.stick_us(self.flown_hover)
        return round(min(max(stick, p.throttle_min_us), p.throttle_max_us))

    def update(self, setpoint_m: float, estimate: AltEstimate, roll_rad: float, pitch_rad: float,
               dt_s: float, *, on_floor: bool = False, rate_mps: float | None = None,
               sink_limit_mps2: float | None = None) -> AltControlOutput:
        """One step: setpoint altitude (up, m) and the estimate → throttle stick PWM.

        `on_floor`: the vehicle stands on the floor, so thrust below its weight changes nothing
        and the integrator must not wind up against it. `rate_mps`: the setpoint profile's speed
        for this move (None: the controller's own). `sink_limit_mps2` (≥ 0): the most downward
        acceleration the command may ask below the learned hover (and below the integrator
        when it trims that hover down); None: only the PID's own limits."""
        p = self.params
        alt = _flown_alt(estimate)
        error = setpoint_m - alt
        integrate = not (on_floor or (self._clamped > 0 and error > 0.0)
                         or (self._clamped < 0 and error < 0.0))
        vel = estimate.vel_mps if estimate.control_vel_mps is None else estimate.control_vel_mps
        # Counted from the learned hover, less any trim the integrator takes off it (a hover
        # learned too high): never from a trim it adds, for an integrator wound up on a wrong
        # estimate (carpet) is no trim, and a floor above the hover would hold a climb for ever.
        out_min = (None if sink_limit_mps2 is None
                   else min(self.pid.integrator, 0.0) - sink_limit_mps2)
        terms: PidTerms = self.pid.update(setpoint_m, alt, dt_s, measurement_rate=vel,
                                          integrate=integrate, slew_per_s=rate_mps,
                                          out_min=out_min)
        tilt = self._tilt(roll_rad, pitch_rad)
        thrust = p.mass_kg * (GRAVITY_MPS2 + terms.out) / tilt
        motor = self.hover_throttle * thrust / (p.mass_kg * GRAVITY_MPS2)
        stick = self.curve.stick_us(motor)
        throttle_us = round(min(max(stick, p.throttle_min_us), p.throttle_max_us))
        self._clamped = 1 if stick > p.throttle_max_us else -1 if stick < p.throttle_min_us else 0
        g = p.gains
        full = (self._clamped > 0 or terms.out >= g.out_max
                or (terms.error >= g.error_max and terms.i >= p.blocked_climb_i_share * g.i_max))
        blocked = full and not on_floor and vel < p.blocked_climb_vel_mps
        self.blocked_climb_s = self.blocked_climb_s + dt_s if blocked else 0.0
        if not on_floor:  # on the floor the throttle says nothing about the hover throttle
            self._learn_hover(motor * tilt, terms, estimate, dt_s)
        return AltControlOutput(
            setpoint_m=terms.shaped_target,
            alt_m=alt,
            error_m=terms.error,
            p=terms.p,
            i=terms.i,
            d=terms.d,
            accel_cmd_mps2=terms.out,
            thrust_n=thrust,
            motor_throttle=motor,
            hover_throttle=self.hover_throttle,
            throttle_us=throttle_us,
            saturated=terms.saturated or self._clamped != 0,
        )

    def _learn_hover(self, level_motor: float, terms: PidTerms, est: AltEstimate,
                     dt_s: float) -> None:
        p = self.params
        steady = (abs(est.vel_mps) < p.hover_learn_max_vel_mps
                  and abs(terms.error) < p.hover_learn_max_err_m
                  and not terms.saturated and not est.coasting and self._clamped == 0)
        if not steady:
            return
        kf = dt_s / (dt_s + p.flown_hover_tc_s)
        self.flown_hover += kf * (level_motor - self.flown_hover)
        # the throttle that holds the vehicle level (without the PID's acceleration) is hover;
        # the integrator then hands its share over to the learned value
        k = dt_s / (dt_s + p.hover_learn_tc_s)
        new = self.hover_throttle + k * (level_motor - self.hover_throttle)
        new = min(max(new, p.hover_min), p.hover_max)
        # keep the total command unchanged: what hover gains, the integrator gives back
        scale = GRAVITY_MPS2 / self.hover_throttle
        shift = (new - self.hover_throttle) * scale
        self.pid.shift_integrator(-shift)
        self.hover_throttle = new


def _flown_alt(est: AltEstimate) -> float:
    """The altitude the hold acts on: the estimate's control altitude when it has one."""
    return est.alt_m if est.control_alt_m is None else est.control_alt_m
