"""Angle → rate → PID attitude controller (ArduCopter's STB_* P gains feeding RATE_* PIDs)."""

from __future__ import annotations

import math

from sitl.autopilot.gains import Gains
from sitl.autopilot.pid import Pid
from sitl.tick_record import tick_record

RATE_MAX_RADS = math.radians(180.0)  # ANGLE_RATE_MAX of 3.2.1 (18000 cdeg/s)
YAW_OUT_MAX = 0.4  # yaw authority kept below roll/pitch, as the motors' yaw headroom


@tick_record
class AttitudeOutput:
    """Normalised roll, pitch, yaw demands (±1) and the rate targets behind them."""

    roll: float
    pitch: float
    yaw: float
    rate_target_rads: tuple[float, float, float]


def _wrap_pi(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class AttitudeController:
    """Levels and steers the vehicle to target lean angles and a yaw rate."""

    def __init__(self, gains: Gains) -> None:
        self.gains = gains
        self._roll = Pid(gains.rate_rll)
        self._pitch = Pid(gains.rate_pit)
        self._yaw = Pid(gains.rate_yaw)
        self.yaw_target_rad = 0.0

    def set_gains(self, gains: Gains) -> None:
        """Adopt new gains (integrators restart)."""
        self.gains = gains
        self._roll = Pid(gains.rate_rll)
        self._pitch = Pid(gains.rate_pit)
        self._yaw = Pid(gains.rate_yaw)

    def relax(self, yaw_rad: float) -> None:
        """On the ground: clear integrators and hold the current heading."""
        self._roll.reset()
        self._pitch.reset()
        self._yaw.reset()
        self.yaw_target_rad = yaw_rad

    def update(
        self,
        target_roll_rad: float,
        target_pitch_rad: float,
        pilot_yaw_rate_rads: float,
        euler_rad: tuple[float, float, float],
        gyro_rads: tuple[float, float, float],
        dt_s: float,
        saturated: bool = False,
    ) -> AttitudeOutput:
        """One step: angle errors to body-rate targets, rate errors through the PIDs."""
        g = self.gains
        roll, pitch, yaw = euler_rad
        self.yaw_target_rad = _wrap_pi(self.yaw_target_rad + pilot_yaw_rate_rads * dt_s)
        yaw_err = _wrap_pi(self.yaw_target_rad - yaw)
        # keep the heading target within reach so a stuck yaw doesn't wind up a huge turn
        if abs(yaw_err) > math.radians(30.0):
            yaw_err = math.copysign(math.radians(30.0), yaw_err)
            self.yaw_target_rad = _wrap_pi(yaw + yaw_err)

        def lim(x: float) -> float:
            # min(RATE_MAX_RADS, max(-RATE_MAX_RADS, x)) without the calls (same result)
            x = x if x > -RATE_MAX_RADS else -RATE_MAX_RADS
            return x if x < RATE_MAX_RADS else RATE_MAX_RADS

        # Euler-angle rates to body rates (small-angle exact for roll/pitch, yaw via tilt)
        rr_e = lim(g.stb_rll_p * (target_roll_rad - roll))
        pr_e = lim(g.stb_pit_p * (target_pitch_rad - pitch))
        yr_e = lim(g.stb_yaw_p * yaw_err + pilot_yaw_rate_rads)
        sr, cr = math.sin(roll), math.cos(roll)
        sp, cp = math.sin(pitch), math.cos(pitch)
        p_t = rr_e - sp * yr_e
        q_t = cr * pr_e + sr * cp * yr_e
        r_t = -sr * pr_e + cr * cp * yr_e
        gx, gy, gz = gyro_rads
        out_r = self._roll.update(p_t - gx, dt_s, limit_i=saturated).total
        out_p = self._pitch.update(q_t - gy, dt_s, limit_i=saturated).total
        out_y = self._yaw.update(r_t - gz, dt_s, limit_i=saturated).total
        # min(hi, max(-hi, out)) each, without the calls (same result)
        out_r = out_r if out_r > -1.0 else -1.0
        out_p = out_p if out_p > -1.0 else -1.0
        out_y = out_y if out_y > -YAW_OUT_MAX else -YAW_OUT_MAX
        return AttitudeOutput(
            roll=out_r if out_r < 1.0 else 1.0,
            pitch=out_p if out_p < 1.0 else 1.0,
            yaw=out_y if out_y < YAW_OUT_MAX else YAW_OUT_MAX,
            rate_target_rads=(p_t, q_t, r_t),
        )
