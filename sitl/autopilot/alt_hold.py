"""ArduCopter's vertical position controller (AC_PosControl z axis), in cm as the firmware.

position error × POS_Z_P → climb-rate target; velocity error × VEL_Z_P → acceleration target;
acceleration error → PID (ACCEL_Z P/I/D/IMAX) whose output, in 1/1000 of throttle, is added to
the hover throttle. The hover throttle is learned while holding still (Copter 3.2.1's
throttle_average, 4.x's MOT_HOVER_LEARN), which is what keeps the integrator small.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sitl.autopilot.gains import Gains
from sitl.autopilot.pid import Pid, PidTerms
from sitl.tick_record import tick_record

ACCEL_Z_MAX_CMSS = 250.0  # target acceleration bound (PILOT_ACCEL_Z)
HOVER_LEARN_TC_S = 2.0
LEASH_CM = 300.0  # max altitude error kept in the target, as the firmware's leash
TAKEOFF_JUMP_CM = 20.0  # AC_PosControl's takeoff target jump


@dataclass(frozen=True)
class CascadeShape:
    """Where the two firmwares' cascades differ (AC_PosControl 3.2 vs 4.x), fitted to the
    `althold-steps` fixtures.

    3.2.1 has no velocity feed-forward: the climb rate target is only POS_Z_P × the position
    error, so a stick step reaches its rate with a ≈ 1 s lag (fixture: 0.80 of the rate 2 s into
    a 1900 µs step, 0.91 at 4 s); it low-passes the velocity error at 4 Hz
    (POSCONTROL_VEL_ERROR_CUTOFF_FREQ) and the acceleration error at 2 Hz
    (POSCONTROL_THROTTLE_CUTOFF_FREQ). 4.x feeds the pilot's rate forward (its rate within 1 s,
    fixture) and filters the errors at PSC_VELZ_FLTE 5 Hz and PSC_ACCZ_FLTE 20 Hz.
    Both read the accelerometer through a 20 Hz low-pass (3.2.1: the MPU-6000's DLPF;
    4.x: INS_ACCEL_FILTER).
    """

    velocity_feed_forward: bool
    vel_err_hz: float
    acc_err_hz: float
    accel_in_hz: float = 20.0
    jerk_cmsss: float = 0.0  # 4.x shapes the pilot's rate (PSC_JERK_Z 5 m/s³); 0 = not at all


SHAPE_APM25 = CascadeShape(velocity_feed_forward=False, vel_err_hz=4.0, acc_err_hz=2.0)
SHAPE_COPTER4 = CascadeShape(
    velocity_feed_forward=True, vel_err_hz=5.0, acc_err_hz=20.0, jerk_cmsss=500.0
)


def _alpha(dt_s: float, hz: float) -> float:
    return dt_s / (dt_s + 1.0 / (2.0 * math.pi * hz))


def _sqrt_shape(error: float, p: float, limit: float) -> float:
    """AP's sqrt_controller: p × error near zero, the √ of a constant deceleration beyond."""
    linear = limit / (p * p)
    if error > linear:
        return math.sqrt(2.0 * limit * (error - linear / 2.0))
    if error < -linear:
        return -math.sqrt(2.0 * limit * (-error - linear / 2.0))
    return p * error


class RateShaper:
    """4.x's input shaping of the pilot's climb rate (shape_vel_accel): the desired velocity
    moves toward the stick's rate with acceleration at most PILOT_ACCEL_Z and its change at most
    PSC_JERK_Z. So a climb starts and stops smoothly and a centred stick brakes over
    ≈ v² / 2a plus the jerk ramp: 1.5 m from 1.88 m/s (fixture: +1.5 m after 1900 µs)."""

    def __init__(self, accel_max_cmss: float, jerk_cmsss: float) -> None:
        self.accel_max = accel_max_cmss
        self.jerk = jerk_cmsss
        self.vel_cms = 0.0
        self.accel_cmss = 0.0

    def reset(self, vel_cms: float = 0.0) -> None:
        """Start from `vel_cms` with no acceleration."""
        self.vel_cms = vel_cms
        self.accel_cmss = 0.0

    def update(self, rate_cms: float, dt_s: float) -> float:
        """Advance by `dt_s` toward `rate_cms`; returns the distance moved (cm)."""
        a_cmd = _sqrt_shape(rate_cms - self.vel_cms, self.jerk / self.accel_max, self.jerk)
        a_cmd = min(self.accel_max, max(-self.accel_max, a_cmd))
        step = self.jerk * dt_s
        self.accel_cmss += min(step, max(-step, a_cmd - self.accel_cmss))
        moved = self.vel_cms * dt_s + 0.5 * self.accel_cmss * dt_s * dt_s
        self.vel_cms += self.accel_cmss * dt_s
        return moved


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

    def __init__(
        self, gains: Gains, hover_throttle: float, shape: CascadeShape = SHAPE_COPTER4
    ) -> None:
        self.gains = gains
        self.hover_throttle = hover_throttle
        self.shape = shape
        self.target_alt_cm = 0.0
        self._pid = Pid(gains.acc_z)
        self._acc_filtered = 0.0
        self._vel_err = 0.0
        self._accel_in: float | None = None
        self._shaper = RateShaper(ACCEL_Z_MAX_CMSS, shape.jerk_cmsss or 1.0)
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
        self._vel_err = 0.0
        self._shaper.reset()

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
        shape = self.shape
        blocked = (self._limit_high and climb_rate_cms > 0) or (
            self._limit_low and climb_rate_cms < 0
        )
        if shape.jerk_cmsss > 0.0:
            moved = self._shaper.update(0.0 if blocked else climb_rate_cms, dt_s)
            self.target_alt_cm += moved
            feed_forward = self._shaper.vel_cms
        else:
            if not blocked:
                self.target_alt_cm += climb_rate_cms * dt_s
            feed_forward = climb_rate_cms
        self.target_alt_cm = min(alt_cm + LEASH_CM, max(alt_cm - LEASH_CM, self.target_alt_cm))
        vel_target = self._sqrt_controller(self.target_alt_cm - alt_cm)
        if shape.velocity_feed_forward:
            vel_target += feed_forward
        vmax = g.pilot_velz_max_cms
        vel_target = min(vmax, max(-vmax, vel_target))
        self._vel_err += _alpha(dt_s, shape.vel_err_hz) * (vel_target - vel_cms - self._vel_err)
        acc_target = g.vel_z_p * self._vel_err
        if shape.jerk_cmsss > 0.0:
            acc_target += self._shaper.accel_cmss  # 4.x feeds the shaped acceleration forward
        acc_target = min(ACCEL_Z_MAX_CMSS, max(-ACCEL_Z_MAX_CMSS, acc_target))
        if self._accel_in is None:
            self._accel_in = accel_cmss
        self._accel_in += _alpha(dt_s, shape.accel_in_hz) * (accel_cmss - self._accel_in)
        err = acc_target - self._accel_in
        self._acc_filtered += _alpha(dt_s, shape.acc_err_hz) * (err - self._acc_filtered)
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
        self._terrain_cm: float | None = None

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
            # engaged: the surface distance the altitude target stands for (both firmwares add
            # the altitude error, so a vehicle still closing on its target does not re-aim)
            self.target_cm = self.sonar_alt_cm + (alt_target_cm - alt_cm)
        self.target_cm += target_rate_cms * dt_s
        self.target_cm = min(
            self.sonar_alt_cm + LEASH_CM, max(self.sonar_alt_cm - LEASH_CM, self.target_cm)
        )
        error = (self.target_cm - self.sonar_alt_cm) - (alt_target_cm - alt_cm)
        correction = min(self.VELZ_MAX_CMS, max(-self.VELZ_MAX_CMS, error * gain))
        return target_rate_cms + correction

    def terrain_shift(self, alt_cm: float, dt_s: float, tc_s: float) -> float:
        """4.x's surface tracking (SURFTRAK_MODE 1): the floor's height in the estimator's frame,
        alt − rangefinder, low-passed with SURFTRAK_TC, moves the position target by as much as
        it changes. Acquiring the floor again starts from the current offset, so nothing jumps
        (3.2.1's tracker, above, re-targets the surface distance instead). Returns the shift, cm.
        """
        if not self.healthy:
            self._terrain_cm = None
            return 0.0
        assert self.sonar_alt_cm is not None
        measured = alt_cm - self.sonar_alt_cm
        if self._terrain_cm is None:
            self._terrain_cm = measured
            return 0.0
        before = self._terrain_cm
        self._terrain_cm += dt_s / (max(tc_s, dt_s) + dt_s) * (measured - before)
        return self._terrain_cm - before

