"""ArduCopter's vertical position controller (AC_PosControl z axis), in cm as the firmware.

position error × POS_Z_P → climb-rate target; velocity error × VEL_Z_P → acceleration target;
acceleration error → PID (ACCEL_Z P/I/D/IMAX) whose output, in 1/1000 of throttle, is added to
the hover throttle. The hover throttle is learned while holding still (Copter 3.2.1's
throttle_average, 4.x's MOT_HOVER_LEARN), which is what keeps the integrator small.
"""

from __future__ import annotations

import math

from sitl.autopilot.gains import Gains
from sitl.autopilot.pid import Pid, PidTerms
from sitl.tick_record import tick_record

ACCEL_Z_MAX_CMSS = 250.0  # target acceleration bound (PILOT_ACCEL_Z)
ACCEL_FILT_HZ = 20.0
HOVER_LEARN_TC_S = 2.0
LEASH_CM = 300.0  # max altitude error kept in the target, as the firmware's leash
TAKEOFF_JUMP_CM = 20.0  # AC_PosControl's takeoff target jump


@tick_record
class AltHoldOutput:
    """One step's result: throttle 0..1 plus the cascade's intermediate targets."""

    throttle: float
    target_alt_cm: float
    target_climb_cms: float
    target_accel_cmss: float
    accel_terms: PidTerms


class AltitudeController:
    """Position → velocity → acceleration cascade driving the collective throttle."""

    def __init__(self, gains: Gains, hover_throttle: float) -> None:
        self.gains = gains
        self.hover_throttle = hover_throttle
        self.target_alt_cm = 0.0
        self._pid = Pid(gains.acc_z)
        self._acc_filtered = 0.0
        self._limit_low = False
        self._limit_high = False

    def set_gains(self, gains: Gains) -> None:
        """Adopt new gains, keeping the integrator."""
        integrator = self._pid.integrator
        self.gains = gains
        self._pid = Pid(gains.acc_z)
        self._pid._integrator = max(-gains.acc_z.imax, min(gains.acc_z.imax, integrator))

    def reset(self, alt_cm: float, throttle_now: float, vel_cms: float = 0.0) -> None:
        """Start holding where a climb at `vel_cms` can stop (set_target_to_stopping_point_z),
        without a throttle jump (the integrator absorbs the difference)."""
        self.target_alt_cm = alt_cm + self._stopping_distance_cm(vel_cms)
        self._pid.reset()
        self._pid._integrator = (throttle_now - self.hover_throttle) * 1000.0
        self._acc_filtered = 0.0

    def init_takeoff(self, alt_cm: float) -> None:
        """Leaving the ground in ALT_HOLD: aim a little above and drop a negative I term,
        so the motors go straight to hover rather than winding the integrator up first."""
        self.target_alt_cm = alt_cm + TAKEOFF_JUMP_CM
        if self._pid.integrator < 0.0:
            self._pid.reset_i()

    def _stopping_distance_cm(self, vel_cms: float) -> float:
        p = max(self.gains.pos_z_p, 1e-3)
        linear_vel = ACCEL_Z_MAX_CMSS / p
        if abs(vel_cms) <= linear_vel:
            return vel_cms / p
        linear_dist = ACCEL_Z_MAX_CMSS / (2.0 * p * p)
        d = linear_dist + vel_cms * vel_cms / (2.0 * ACCEL_Z_MAX_CMSS)
        return math.copysign(d, vel_cms)

    def _sqrt_controller(self, error_cm: float) -> float:
        """AC_PosControl's position → velocity: linear near the target, sqrt beyond."""
        p = self.gains.pos_z_p
        linear_dist = ACCEL_Z_MAX_CMSS / (2.0 * p * p) if p > 0 else 0.0
        if error_cm > linear_dist:
            return math.sqrt(2.0 * ACCEL_Z_MAX_CMSS * (error_cm - linear_dist / 2.0))
        if error_cm < -linear_dist:
            return -math.sqrt(2.0 * ACCEL_Z_MAX_CMSS * (-error_cm - linear_dist / 2.0))
        return p * error_cm

    def update(
        self,
        climb_rate_cms: float,
        alt_cm: float,
        vel_cms: float,
        accel_cmss: float,
        dt_s: float,
        tilt_cos: float = 1.0,
    ) -> AltHoldOutput:
        """Move the target at `climb_rate_cms` and return the throttle to follow it."""
        g = self.gains
        # don't let the target run away while the motors are saturated
        if not (
            (self._limit_high and climb_rate_cms > 0) or (self._limit_low and climb_rate_cms < 0)
        ):
            self.target_alt_cm += climb_rate_cms * dt_s
        self.target_alt_cm = min(alt_cm + LEASH_CM, max(alt_cm - LEASH_CM, self.target_alt_cm))
        vel_target = self._sqrt_controller(self.target_alt_cm - alt_cm) + climb_rate_cms
        vmax = g.pilot_velz_max_cms
        vel_target = min(vmax, max(-vmax, vel_target))
        acc_target = g.vel_z_p * (vel_target - vel_cms)
        acc_target = min(ACCEL_Z_MAX_CMSS, max(-ACCEL_Z_MAX_CMSS, acc_target))
        alpha = dt_s / (dt_s + 1.0 / (2.0 * math.pi * ACCEL_FILT_HZ))
        err = acc_target - accel_cmss
        self._acc_filtered += alpha * (err - self._acc_filtered)
        terms = self._pid.update(
            self._acc_filtered, dt_s, limit_i=self._limit_high or self._limit_low
        )
        thr = self.hover_throttle + terms.total / 1000.0
        # tilt compensation: more collective when leaning (as the firmware's angle boost)
        thr /= max(0.5, tilt_cos)
        self._limit_high = thr >= 1.0
        self._limit_low = thr <= g.thr_min
        thr = min(1.0, max(g.thr_min, thr))
        return AltHoldOutput(thr, self.target_alt_cm, vel_target, acc_target, terms)

    @property
    def limit_low(self) -> bool:
        """The throttle demand is at its lower bound (used by the land detector)."""
        return self._limit_low

    def learn_hover(self, throttle: float, climb_ms: float, dt_s: float) -> None:
        """Track the throttle that holds altitude while the vehicle is nearly still vertically."""
        if abs(climb_ms) < 0.6:
            alpha = dt_s / (HOVER_LEARN_TC_S + dt_s)
            self.hover_throttle = min(
                0.8, max(0.1, self.hover_throttle + alpha * (throttle - self.hover_throttle))
            )


class SurfaceTracker:
    """Copter 3.2.1's sonar surface tracking: keeps the sonar distance where the pilot left it.

    Sonar reads are trusted after 3 good reads in a row and only up to 60 % of its range.
    The correction to the climb rate is (target − sonar) × RNGFND_GAIN, bounded to 1.5 m/s.
    """

    HEALTH_MAX = 3
    VELZ_MAX_CMS = 150.0

    def __init__(self) -> None:
        self.health = 0
        self.sonar_alt_cm: float | None = None
        self.target_cm: float | None = None

    def reading(self, distance_m: float | None, tilt_cos: float, gains: Gains) -> None:
        """Feed a new sonar reading (None = no echo / out of range)."""
        ok = (
            distance_m is not None
            and gains.rng_min_m < distance_m < 0.6 * gains.rng_max_m
            and tilt_cos > 0.7
        )
        if ok:
            assert distance_m is not None
            self.sonar_alt_cm = distance_m * tilt_cos * 100.0
            self.health = min(self.HEALTH_MAX, self.health + 1)
        else:
            self.health = 0

    @property
    def healthy(self) -> bool:
        """True once enough good reads arrived."""
        return self.health >= self.HEALTH_MAX and self.sonar_alt_cm is not None

    def climb_rate(
        self,
        target_rate_cms: float,
        dt_s: float,
        gain: float,
        alt_target_cm: float,
        alt_cm: float,
    ) -> float:
        """Pilot climb rate corrected to keep the surface distance.

        As in 3.2.1, the part of the distance error the altitude controller is already
        correcting (target altitude − altitude) is removed, so the two loops don't fight.
        """
        if not self.healthy:
            self.target_cm = None
            return target_rate_cms
        assert self.sonar_alt_cm is not None
        if self.target_cm is None:
            self.target_cm = self.sonar_alt_cm
        self.target_cm += target_rate_cms * dt_s
        self.target_cm = min(
            self.sonar_alt_cm + LEASH_CM, max(self.sonar_alt_cm - LEASH_CM, self.target_cm)
        )
        error = (self.target_cm - self.sonar_alt_cm) - (alt_target_cm - alt_cm)
        correction = min(self.VELZ_MAX_CMS, max(-self.VELZ_MAX_CMS, error * gain))
        return target_rate_cms + correction
