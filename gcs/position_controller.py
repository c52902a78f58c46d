"""Horizontal position hold and yaw hold from motion capture, on ArduCopter's sticks.

Per axis (north, east) a PID turns the position error into a horizontal acceleration; that is
rotated into the heading frame (forward, right) and turned into lean angles (tan θ = a/g), then
into stick PWM at ArduCopter's ANGLE_MAX per full deflection. In ArduCopter, pitch stick LOW is
nose down (forward) and roll stick HIGH is roll right; the yaw stick commands a yaw rate.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from firmware_link.records import MocapPose, Quat, RcCommand
from gcs.estimation import GRAVITY_MPS2
from gcs.pid import Pid, PidGains


def _default_xy_gains() -> PidGains:
    # The set point moves on a trapezoidal profile (0.7 m/s, 1 m/s²) whose acceleration goes
    # straight to the lean, and kd damps the rate against the profile's. The lean follows the
    # stick some 0.25 s late and the vehicle its lean later still, so the loop acts on the
    # profile 0.45 s ahead: without that lead braking began too late, and a 0.1 m step (the
    # flock's) overshot by 74-139 %, a 0.5 m leg by about 50 % (lockstep, gcs.position_legs,
    # seeds 1-3, both profiles). Stiffer gains with the lead settled faster still (kp 2.5, kd
    # 3.5) but turned EPBHA's table approach into a detour past the table's legs in 3 of 5 seeds.
    return PidGains(kp=1.2, ki=0.1, kd=2.4, i_max=0.5, out_min=-2.5, out_max=2.5,
                    d_filter_hz=3.0, setpoint_slew_per_s=0.7, setpoint_accel_per_s2=1.0,
                    ff_accel=1.0, lead_s=0.45)


@dataclass(frozen=True, slots=True)
class PositionControllerParams:
    """Tuning of the horizontal loop; stick scaling as ArduCopter's defaults."""

    gains_xy: PidGains = field(default_factory=_default_xy_gains)
    max_lean_rad: float = math.radians(15.0)
    angle_max_rad: float = math.radians(45.0)  # ANGLE_MAX: lean at full stick
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
    """One step of the horizontal loop."""

    error_n_m: float
    error_e_m: float
    acc_fwd_mps2: float
    acc_right_mps2: float
    pitch_rad: float  # commanded, positive nose up
    roll_rad: float  # commanded, positive right
    yaw_error_rad: float
    roll_us: int
    pitch_us: int
    yaw_us: int


def yaw_from_quat(q_nb: Quat) -> float:
    """Heading (rad) of a body→NED quaternion (w, x, y, z), ZYX convention."""
    w, x, y, z = q_nb
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def wrap_pi(a: float) -> float:
    """Angle wrapped to [-π, π)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class PositionController:
    """North/east PIDs → lean angles → roll/pitch sticks; yaw P → yaw-rate stick."""

    def __init__(self, params: PositionControllerParams | None = None) -> None:
        self.params = params or PositionControllerParams()
        self.pid_n = Pid(self.params.gains_xy)
        self.pid_e = Pid(self.params.gains_xy)
        self._yaw_hold: float | None = None

    def reset(self) -> None:
        """Forget integrators, filters and the held heading."""
        self.pid_n.reset()
        self.pid_e.reset()
        self._yaw_hold = None

    def _stick(self, value: float, full_scale: float, deadzone_us: int = 0) -> int:
        half = self.params.stick_half_range_us
        frac = max(-1.0, min(1.0, value / full_scale))
        if abs(frac) < 1e-9:  # rounding noise of the heading rotation, not a command
            return 1500
        # the vehicle maps (pwm - 1500 -+ dz) over (half - dz) to the full deflection
        return round(1500 + math.copysign(deadzone_us, frac) + frac * (half - deadzone_us))

    def update(self, setpoint: PositionSetpoint, pose: MocapPose, dt_s: float) -> PositionCommand:
        """One step against the latest motion-capture pose."""
        p = self.params
        n, e, _ = pose.pos_n
        tn = self.pid_n.update(setpoint.north_m, n, dt_s)
        te = self.pid_e.update(setpoint.east_m, e, dt_s)
        yaw = yaw_from_quat(pose.q_nb)
        c, s = math.cos(yaw), math.sin(yaw)
        fwd = c * tn.out + s * te.out
        right = -s * tn.out + c * te.out
        nose_down = max(-p.max_lean_rad, min(p.max_lean_rad, math.atan2(fwd, GRAVITY_MPS2)))
        roll = max(-p.max_lean_rad, min(p.max_lean_rad, math.atan2(right, GRAVITY_MPS2)))
        if setpoint.yaw_rad is not None:
            self._yaw_hold = setpoint.yaw_rad
        elif self._yaw_hold is None:
            self._yaw_hold = yaw
        yaw_err = wrap_pi(self._yaw_hold - yaw)
        rate = max(-p.yaw_rate_max_rps, min(p.yaw_rate_max_rps, p.yaw_p_per_s * yaw_err))
        return PositionCommand(
            error_n_m=tn.error,
            error_e_m=te.error,
            acc_fwd_mps2=fwd,
            acc_right_mps2=right,
            pitch_rad=-nose_down,
            roll_rad=roll,
            yaw_error_rad=yaw_err,
            roll_us=self._stick(roll, p.angle_max_rad, p.stick_deadzone_us),
            # pitch stick low = nose down: the stick follows the (nose-up positive) pitch angle
            pitch_us=self._stick(-nose_down, p.angle_max_rad, p.stick_deadzone_us),
            yaw_us=self._stick(rate, p.yaw_full_stick_rps),
        )

    @staticmethod
    def apply(cmd: PositionCommand, throttle_us: int) -> RcCommand:
        """The full stick command with the altitude loop's throttle."""
        return RcCommand(roll_us=cmd.roll_us, pitch_us=cmd.pitch_us, throttle_us=throttle_us,
                         yaw_us=cmd.yaw_us)
