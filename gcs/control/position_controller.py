"""Horizontal position hold and yaw hold from motion capture, on ArduCopter's sticks.

Per axis (north, east):

1. a set-point profile (a trapezoid averaged into an S-curve: bounded speed, acceleration
   and jerk) turns a jump of the set point into the acceleration to feed forward and, that
   acceleration's lag later, the reference position and velocity the feedback compares with;
2. an alpha-beta observer turns motion capture's positions, propagated with the acceleration
   motion capture's lean implies, into position and velocity;
3. a PID (P and I on the position error, D on the velocity error; I only while holding, and
   not further into the lean limit) adds the correction to the feed-forward.

The acceleration vector is limited to the lean limit, rotated into the heading frame (forward,
right) and turned into lean angles (tan θ = a/g). Those are the vehicle's true lean; the
autopilot holds its own estimate of the lean at the stick's angle, and that estimate is off
during and after every acceleration (below), so the stick asks for the true lean minus that
offset, measured as motion capture's lean minus the vehicle's reported one. Sticks map to angles
at ArduCopter's ANGLE_MAX per full deflection past RCn_DZ. In ArduCopter, pitch stick LOW is
nose down (forward) and roll stick HIGH is roll right; the yaw stick commands a yaw rate.

Why the lean offset: without GPS the autopilot levels its attitude estimate on the accelerometer,
taking the specific force for gravity (DCM's proportional correction, 0.5 rad/s per rad; EKF
without aiding behaves alike). A vehicle accelerating at a leans truly by atan(a/g) while its
accelerometer reads straight down the body, so the estimate creeps towards level at 0.5 rad/s
per rad of lean: the offset is the acceleration low-passed over about 2 s. Recorded on the
bundled SITL (MCAP /vehicle/sim_truth against /vehicle/attitude) it reached 2.7° during a 2 m
leg and stayed 0.3-0.6° for seconds after it, 0.05-0.1 m/s² of unasked acceleration: the vehicle
stopped 5-15 cm short or past the spot and crept in as the offset decayed. Motion capture sees
the true attitude, so the offset is measured and taken out where it enters, not left for an
integrator that cannot follow a disturbance which changes sign within each leg.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from firmware_link.records import MocapPose, RcCommand
from gcs.control.attitude import lean_accel, roll_pitch_from_quat, wrap_pi, yaw_from_quat
from gcs.control.axis_filters import AlphaBeta, SetpointProfile
from gcs.estimation import GRAVITY_MPS2


@dataclass(frozen=True, slots=True)
class PositionGains:
    """Per-axis gains of the horizontal loop (the same north and east), SI units.

    The plant, from the acceleration asked to the position seen: the vehicle's lean follows
    the stick about 0.05 s late with a 0.18 s time constant on both profiles (a fit of
    /vehicle/attitude to the sticks of recorded legs), motion capture adds 10 ms and the tick
    half a period, so a ≈ e^(-0.075 s) / (0.18 s + 1) · a_asked. With the delay as a Padé term
    the PID's loop (D on the observed velocity, which the lean-aided observer gives without a
    lag of its own) has five poles; kp 2.5, kd 2.2, ki 1.2 put the four that matter at about
    -1.1 ± 0.7j and -1.1 ± 1.6j (1/s), damping ≥ 0.55: of the gains with damping ≥ 0.5 the set
    whose slowest pole is fastest (a grid search). The 0.25 s lag caps that near 1.1/s, so the
    loop alone settles in ~3.5 s; a leg is flown by the profile and its feed-forward, and the
    feedback mops up what the lag model misses. Lockstep legs (seeds 1-3, both profiles): a
    lead of 0.15 s overshot a 0.5 m leg by 13-20 %, 0.35 s settled 0.5 s later; without the
    ramp (a bare trapezoid) 10-16 %.

    The profile: 1 m/s and 1.5 m/s² (8.7° of lean, leaving 6° of the 15° limit to the
    feedback) bring a 0.5 m leg in 2·√(0.5/1.5) + ramp_s + lead_s = 1.7 s and a 2 m leg in
    2/1 + 1/1.5 + 0.55 = 3.2 s, inside the mission issue's 2 s and 4 s.
    """

    kp: float = 2.5  # m/s² per m of position error
    ki: float = 1.2  # m/s² per m·s of position error (integrated while holding only)
    kd: float = 2.2  # m/s² per m/s of velocity error
    i_max: float = 0.5  # m/s²: the integrator's reach, about 3° of lean
    # the profile: cruise speed (m/s) and acceleration (m/s²); names as the shared PID's, so a
    # mission's [station.position.gains_xy] table keeps its meaning
    setpoint_slew_per_s: float = 1.0
    setpoint_accel_per_s2: float = 1.5
    # the profile runs this far ahead of the reference the feedback compares with: its
    # acceleration reaches the vehicle's lean after the vehicle's lag, as the feedback expects
    lead_s: float = 0.25
    ramp_s: float = 0.3  # s: the profile's acceleration ramps over this (jerk = accel / ramp_s)
    error_max: float = 0.5  # m: the P and I terms see no more than this (a far jump's leash)
    observer_hz: float = 3.0  # velocity observer's corner (alpha-beta, critically damped)

    def __post_init__(self) -> None:
        if min(self.kp, self.ki, self.kd, self.i_max, self.lead_s, self.ramp_s) < 0.0:
            raise ValueError(f"gains, i_max, lead_s and ramp_s must be >= 0: {self}")
        if min(self.setpoint_slew_per_s, self.setpoint_accel_per_s2, self.error_max,
               self.observer_hz) <= 0.0:
            raise ValueError("the profile's speed and acceleration, error_max and observer_hz "
                             "must be > 0")


@dataclass(frozen=True, slots=True)
class PositionControllerParams:
    """Tuning of the horizontal loop; stick scaling as ArduCopter's defaults."""

    gains_xy: PositionGains = field(default_factory=PositionGains)
    max_lean_rad: float = math.radians(15.0)
    angle_max_rad: float = math.radians(45.0)  # ANGLE_MAX: lean at full stick
    # the autopilot's attitude estimate is trusted to be off by no more than this; a larger
    # difference from motion capture is a fault of one of them, not a lean to fly
    lean_offset_max_rad: float = math.radians(4.0)
    lean_offset_tc_s: float = 0.1  # smoothing of that difference (it moves over ~2 s)
    # the velocity observer takes motion capture's lean as the acceleration between fixes
    observe_lean: bool = True
    yaw_p_per_s: float = 1.5
    yaw_rate_max_rps: float = math.radians(60.0)
    yaw_full_stick_rps: float = math.radians(202.5)  # ACRO_YAW_P 4.5 × 45°/s
    stick_half_range_us: int = 500
    # RC1_DZ/RC2_DZ: ArduCopter reads +-30 us round centre as zero lean; without stepping over
    # it, small corrections vanish and the hold limit-cycles (about 0.5 m on the bundled SITL)
    stick_deadzone_us: int = 30

    def __post_init__(self) -> None:
        if not 0.0 < self.max_lean_rad <= self.angle_max_rad:
            raise ValueError("need 0 < max_lean_rad <= angle_max_rad")
        if self.lean_offset_max_rad < 0.0 or self.lean_offset_tc_s < 0.0:
            raise ValueError("lean_offset_max_rad and lean_offset_tc_s must be >= 0")


# What the vehicle's stick mapping is made of: full-stick lean and the roll/pitch deadzones.
# ArduCopter 3.2.1 ships 45° and 30 µs, 4.7 30° and 20 µs (fixtures' parameter lists); a station
# that assumed one on the other would lean 2/3 or 3/2 of what it asks for.
STICK_PARAMS = ("ANGLE_MAX", "RC1_DZ", "RC2_DZ")


def with_vehicle_sticks(params: PositionControllerParams,
                        values: Mapping[str, float]) -> PositionControllerParams:
    """`params` with the stick mapping the vehicle reported (ANGLE_MAX in centidegrees)."""
    angle_max = math.radians(values["ANGLE_MAX"] / 100.0)
    deadzone = round(max(values["RC1_DZ"], values["RC2_DZ"]))
    if not 0.0 < angle_max <= math.radians(90.0) or not 0 <= deadzone < params.stick_half_range_us:
        raise ValueError(f"vehicle stick mapping ANGLE_MAX {values['ANGLE_MAX']:g}, "
                         f"RC1_DZ/RC2_DZ {deadzone} is not one a station can fly")
    return replace(params, angle_max_rad=angle_max, stick_deadzone_us=deadzone,
                   max_lean_rad=min(params.max_lean_rad, angle_max))


@dataclass(frozen=True, slots=True)
class PositionSetpoint:
    """Where to hold: NED north/east (m) and yaw (rad, None = keep the present heading)."""

    north_m: float
    east_m: float
    yaw_rad: float | None = None


@dataclass(frozen=True, slots=True)
class PositionCommand:
    """One step of the horizontal loop: what it saw, each term, and the sticks."""

    error_n_m: float  # reference - observed position
    error_e_m: float
    acc_fwd_mps2: float  # after the lean limit, heading frame
    acc_right_mps2: float
    pitch_rad: float  # true lean asked for, positive nose up
    roll_rad: float  # true lean asked for, positive right
    yaw_error_rad: float
    roll_us: int
    pitch_us: int
    yaw_us: int
    ref_n_m: float = 0.0  # the profile's reference position
    ref_e_m: float = 0.0
    vel_n_mps: float = 0.0  # observed velocity
    vel_e_mps: float = 0.0
    ff_n_mps2: float = 0.0  # the profile's acceleration, fed forward
    ff_e_mps2: float = 0.0
    i_n_mps2: float = 0.0  # integrator
    i_e_mps2: float = 0.0
    lean_offset_pitch_rad: float = 0.0  # true lean - the vehicle's estimate, as subtracted
    lean_offset_roll_rad: float = 0.0
    saturated: bool = False  # the lean limit cut the asked acceleration


class _Axis:
    """One horizontal axis: profile, its smoothing and delay lines, observer and integrator.

    The trapezoid's acceleration jumps; a lean cannot (ArduCopter swings it at a bounded rate,
    a 17° swing took the bundled SITL 0.45 s), so the trapezoid is averaged over `ramp_s`:
    a moving average of a trapezoid is an S-curve whose acceleration ramps over `ramp_s` and
    which ends where the trapezoid ends, `ramp_s` later. That curve, `lead_s` ahead, gives the
    feed-forward; `lead_s` later it is the reference the feedback compares with."""

    def __init__(self, g: PositionGains, pos_m: float, dt_s: float) -> None:
        self.g = g
        self.profile = SetpointProfile(g.setpoint_slew_per_s, g.setpoint_accel_per_s2, pos_m)
        n_ramp = max(1, round(g.ramp_s / dt_s))
        n_lead = round(g.lead_s / dt_s) + 1
        self.window: deque[tuple[float, float]] = deque([(pos_m, 0.0)] * n_ramp, maxlen=n_ramp)
        self.ref: deque[tuple[float, float]] = deque([(pos_m, 0.0)] * n_lead, maxlen=n_lead)
        self.obs = AlphaBeta(g.observer_hz, pos_m)
        self.i = 0.0
        self.still_ticks = 0  # ticks since the profile last moved
        self.settled_ticks = n_ramp + n_lead  # ... after which the reference stands still

    def demand(self, target_m: float, dt_s: float) -> tuple[float, float, float, float]:
        """Advance the profile; (error, velocity error, feed-forward, reference position)."""
        before = self.profile.pos_m
        self.profile.step(target_m, dt_s)
        moved = self.profile.pos_m != before or self.profile.vel_mps != 0.0
        self.still_ticks = 0 if moved else self.still_ticks + 1
        v_leaving = self.window[0][1]
        self.window.append((self.profile.pos_m, self.profile.vel_mps))
        n = len(self.window)
        pos = sum(x for x, _ in self.window) / n
        vel = sum(v for _, v in self.window) / n
        ff = (self.profile.vel_mps - v_leaving) / (n * dt_s)  # d/dt of the averaged velocity
        self.ref.append((pos, vel))
        ref_pos, ref_vel = self.ref[0]
        err = min(max(ref_pos - self.obs.pos_m, -self.g.error_max), self.g.error_max)
        return err, ref_vel - self.obs.vel_mps, ff, ref_pos

    @property
    def holding(self) -> bool:
        """The reference stands still (the profile has arrived and its curve with it)."""
        return self.still_ticks >= self.settled_ticks

    def integrate(self, err: float, dt_s: float, pushing_limit: bool) -> None:
        """Integrate while holding only, and not further into a saturated lean; ±i_max.

        The integrator is for a bias of the hold (trim, a misaligned motion-capture body);
        during a move the error is the lag model's, and integrating it wound 0.17 m/s² into a
        2 m leg and swung the vehicle 20 cm back after it."""
        if self.holding and not pushing_limit:
            self.i = min(max(self.i + self.g.ki * err * dt_s, -self.g.i_max), self.g.i_max)


class PositionController:
    """North/east profile + observer + PID → true lean → minus the vehicle's lean error →
    roll/pitch sticks; yaw P → yaw-rate stick."""

    def __init__(self, params: PositionControllerParams | None = None) -> None:
        self.params = params or PositionControllerParams()
        self._axes: tuple[_Axis, _Axis] | None = None
        self._last_fix: tuple[int, float, float] | None = None  # time_usec, north, east
        self._since_fix_s = 0.0
        self._offset = (0.0, 0.0)  # smoothed lean offset: roll, pitch (rad)
        self._yaw_hold: float | None = None

    def reset(self) -> None:
        """Forget profile, observer, integrators, the lean offset and the held heading."""
        self._axes = None
        self._last_fix = None
        self._since_fix_s = 0.0
        self._offset = (0.0, 0.0)
        self._yaw_hold = None

    def _stick(self, value: float, full_scale: float, deadzone_us: int = 0) -> int:
        half = self.params.stick_half_range_us
        frac = max(-1.0, min(1.0, value / full_scale))
        if abs(frac) < 1e-9:  # rounding noise of the heading rotation, not a command
            return 1500
        # the vehicle maps (pwm - 1500 -+ dz) over (half - dz) to the full deflection
        return round(1500 + math.copysign(deadzone_us, frac) + frac * (half - deadzone_us))

    def _observe(self, pose: MocapPose, dt_s: float) -> tuple[_Axis, _Axis]:
        """Feed a new motion-capture fix (a pose seen before is not one) to the observers."""
        n, e, _ = pose.pos_n
        self._since_fix_s += dt_s
        if self._axes is None:
            g = self.params.gains_xy
            self._axes = (_Axis(g, n, dt_s), _Axis(g, e, dt_s))
            self._last_fix, self._since_fix_s = (pose.time_usec, n, e), 0.0
            return self._axes
        last = self._last_fix
        if last is None or (pose.time_usec, n, e) != last:
            # the capture clock's interval when it has one, else the ticks' since the last fix
            interval = (pose.time_usec - last[0]) * 1e-6 if last is not None else 0.0
            if not 0.0 < interval <= 1.0:
                interval = max(self._since_fix_s, 1e-3)
            acc = lean_accel(pose.q_nb) if self.params.observe_lean else (0.0, 0.0)
            for axis, pos, a in zip(self._axes, (n, e), acc, strict=True):
                if interval > 0.25:  # after a gap (mocap lost) the old velocity is stale
                    axis.obs.restart(pos)
                else:
                    axis.obs.fix(pos, interval, a)
            self._last_fix, self._since_fix_s = (pose.time_usec, n, e), 0.0
        return self._axes

    def _lean_offset(self, pose: MocapPose, vehicle_lean_rad: tuple[float, float] | None,
                     dt_s: float) -> tuple[float, float]:
        """True lean (motion capture) minus the vehicle's own estimate, smoothed and bounded."""
        p = self.params
        if vehicle_lean_rad is None:
            return self._offset
        true_roll, true_pitch = roll_pitch_from_quat(pose.q_nb)
        k = dt_s / (dt_s + p.lean_offset_tc_s)
        lim = p.lean_offset_max_rad
        raw = (min(max(true_roll - vehicle_lean_rad[0], -lim), lim),
               min(max(true_pitch - vehicle_lean_rad[1], -lim), lim))
        self._offset = (self._offset[0] + k * (raw[0] - self._offset[0]),
                        self._offset[1] + k * (raw[1] - self._offset[1]))
        return self._offset

    def update(self, setpoint: PositionSetpoint, pose: MocapPose, dt_s: float,
               vehicle_lean_rad: tuple[float, float] | None = None) -> PositionCommand:
        """One step against the latest motion-capture pose. `vehicle_lean_rad` is the vehicle's
        own (roll, pitch) estimate (ATTITUDE); without it the stick asks for the true lean."""
        if dt_s <= 0.0:
            raise ValueError(f"dt_s must be > 0, got {dt_s}")
        p = self.params
        g = p.gains_xy
        ax_n, ax_e = self._observe(pose, dt_s)
        err_n, verr_n, ff_n, ref_n = ax_n.demand(setpoint.north_m, dt_s)
        err_e, verr_e, ff_e, ref_e = ax_e.demand(setpoint.east_m, dt_s)

        def accel(ax: _Axis, err: float, verr: float, ff: float) -> float:
            return ff + g.kp * err + g.kd * verr + ax.i

        a_n = accel(ax_n, err_n, verr_n, ff_n)
        a_e = accel(ax_e, err_e, verr_e, ff_e)
        # the lean limit bounds the acceleration vector, keeping its direction
        a_max = GRAVITY_MPS2 * math.tan(p.max_lean_rad)
        norm = math.hypot(a_n, a_e)
        saturated = norm > a_max
        if saturated:
            a_n, a_e = a_n * a_max / norm, a_e * a_max / norm
        # anti-windup: an error that pushes further into the limit is not integrated
        ax_n.integrate(err_n, dt_s, saturated and err_n * a_n > 0.0)
        ax_e.integrate(err_e, dt_s, saturated and err_e * a_e > 0.0)

        yaw = yaw_from_quat(pose.q_nb)
        c, s = math.cos(yaw), math.sin(yaw)
        fwd = c * a_n + s * a_e
        right = -s * a_n + c * a_e
        nose_down = math.atan2(fwd, GRAVITY_MPS2)
        roll = math.atan2(right, GRAVITY_MPS2)
        off_roll, off_pitch = self._lean_offset(pose, vehicle_lean_rad, dt_s)
        # the autopilot holds its estimate at the stick's angle; the true lean is that plus the
        # offset, so the stick asks for the true lean wanted minus the offset
        stick_roll = roll - off_roll
        stick_pitch = -nose_down - off_pitch
        if setpoint.yaw_rad is not None:
            self._yaw_hold = setpoint.yaw_rad
        elif self._yaw_hold is None:
            self._yaw_hold = yaw
        yaw_err = wrap_pi(self._yaw_hold - yaw)
        rate = max(-p.yaw_rate_max_rps, min(p.yaw_rate_max_rps, p.yaw_p_per_s * yaw_err))
        return PositionCommand(
            error_n_m=err_n,
            error_e_m=err_e,
            acc_fwd_mps2=fwd,
            acc_right_mps2=right,
            pitch_rad=-nose_down,
            roll_rad=roll,
            yaw_error_rad=yaw_err,
            roll_us=self._stick(stick_roll, p.angle_max_rad, p.stick_deadzone_us),
            # pitch stick low = nose down: the stick follows the (nose-up positive) pitch angle
            pitch_us=self._stick(stick_pitch, p.angle_max_rad, p.stick_deadzone_us),
            yaw_us=self._stick(rate, p.yaw_full_stick_rps),
            ref_n_m=ref_n,
            ref_e_m=ref_e,
            vel_n_mps=ax_n.obs.vel_mps,
            vel_e_mps=ax_e.obs.vel_mps,
            ff_n_mps2=ff_n,
            ff_e_mps2=ff_e,
            i_n_mps2=ax_n.i,
            i_e_mps2=ax_e.i,
            lean_offset_pitch_rad=off_pitch,
            lean_offset_roll_rad=off_roll,
            saturated=saturated,
        )

    @staticmethod
    def apply(cmd: PositionCommand, throttle_us: int) -> RcCommand:
        """The full stick command with the altitude loop's throttle."""
        return RcCommand(roll_us=cmd.roll_us, pitch_us=cmd.pitch_us, throttle_us=throttle_us,
                         yaw_us=cmd.yaw_us)
