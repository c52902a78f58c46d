"""The climb-rate hold: the PC's altitude loop flown over the firmware's own ALT_HOLD.

In the direct-throttle hold (`altitude_controller`) the throttle stick is an acceleration:
the last override flown blind keeps accelerating the vehicle until the firmware's failsafe acts
(the real 4.7: 7 µs over hover lifted it 0.37 m in 2.2 s; the real 3.2.1: 1415 µs took it to
6.2 m in 5 s). In ALT_HOLD the stick is a climb rate and mid-stick holds the height, so the
station's estimate (the same sonar/accelerometer fusion) and this loop ask for a climb rate
instead, through `climb_stick.ClimbStickMap`:

    rate = sqrt_shape(target − (alt + lag·v), kp, decel), within ±speed

ArduPilot's own position → velocity shape (linear near the target, a constant deceleration
beyond), so a move or a take-off tapers to zero at the set point and the firmware's velocity
loop does the climbing; `lag·v` is how far the vehicle goes on once the stick centres (v: the
rates flown, through the firmware's lag), so the taper ends where the vehicle stops. Once the
hold has reached its target, it asks no climb that, flown blind until the firmware's failsafe
(3.2.1: 5 s; 4.x: FS_GCS_TIMEOUT, at most 3 s), would end more than `blind_room_m` (0.15 m) over
the target: 0.03 m/s at the set point on 3.2.1. Small errors ask rates the firmware rounds to
zero, so a steady hold sits at mid-stick.

Take-off: the estimate is blind below the rangefinder's minimum range (0.2 m on both
firmwares), so there the loop does not close on it: the rate is the move's own, ramped up at
`accel_mps2`; the firmware climbs at it from the floor. Above `blind_alt_m` the loop closes and
tapers. An estimate that never leaves the blind band while the commanded climb adds up to more
than the band plus `blind_margin_m` is an estimate that is not the vehicle's: the take-off
stops (mid-stick: the firmware holds) and says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from firmware_link.records import Dialect
from gcs.control.climb_stick import ClimbStickMap
from gcs.estimation import AltEstimate


@dataclass(frozen=True, slots=True)
class ClimbRateHoldParams:
    """Tuning of the climb-rate loop (SI units)."""

    kp: float = 3.0  # s⁻¹: climb rate per metre of error near the target
    decel_mps2: float = 0.4  # the taper's deceleration beyond the linear region
    speed_mps: float = 0.5  # a move's climb or sink rate when the request gives none
    accel_mps2: float = 1.0  # how fast the rate asked may change
    # Once within band_m of its target, the hold asks no climb that, flown blind until the
    # firmware's failsafe acts, would end more than blind_room_m over the target: 3.2.1's
    # fixed 5 s, 4.x's FS_GCS_TIMEOUT (the pre-flight's 2 s, at most RC_OVERRIDE_TIME's 3 s).
    # The rest of the 0.3 m is the firmware's braking and the estimate's error.
    band_m: float = 0.1
    blind_room_m: float = 0.15
    blind_apm25_s: float = 5.0
    blind_copter4_s: float = 3.0
    # the rangefinder's minimum range (0.2 m) above the sonar's rest height, with a margin:
    # below this height the estimate cannot see the vehicle rise
    blind_alt_m: float = 0.35
    blind_margin_m: float = 0.4
    # How far behind its climb-rate target the firmware's vehicle runs (s), so how far it goes
    # on once the stick centres: 3.2.1 has no velocity feed-forward (from 1.72 m/s it travelled
    # 1.67 m more, fixtures' althold-steps), 4.x feeds the rate forward and brakes in its
    # shaping (1.5 m from 1.88 m/s, most of it at the full rate; much less from a slow climb)
    lag_apm25_s: float = 1.0
    lag_copter4_s: float = 0.5

    def __post_init__(self) -> None:
        for name in ("kp", "decel_mps2", "speed_mps", "accel_mps2", "band_m", "blind_room_m",
                     "blind_apm25_s", "blind_copter4_s",
                     "blind_margin_m", "lag_apm25_s", "lag_copter4_s"):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")


@dataclass(frozen=True, slots=True)
class ClimbRateOutput:
    """One step of the climb-rate loop."""

    target_m: float
    alt_m: float
    error_m: float
    rate_mps: float  # asked of the loop (before the stick's rounding)
    flown_rate_mps: float  # what the firmware makes of the stick
    throttle_us: int
    blind: bool  # the estimate is in the rangefinder's blind band: open loop


def sqrt_shape(error_m: float, kp: float, decel_mps2: float) -> float:
    """ArduPilot's sqrt_controller: kp·error near zero, √(2·a·(|e| − a/2kp²)) beyond."""
    linear = decel_mps2 / (kp * kp)
    if error_m > linear:
        return math.sqrt(2.0 * decel_mps2 * (error_m - linear / 2.0))
    if error_m < -linear:
        return -math.sqrt(2.0 * decel_mps2 * (-error_m - linear / 2.0))
    return kp * error_m


class ClimbRateHold:
    """Altitude error → climb rate → ALT_HOLD stick."""

    def __init__(self, params: ClimbRateHoldParams, stick: ClimbStickMap) -> None:
        self.params = params
        self.stick = stick
        c4 = stick.dialect is Dialect.COPTER4
        self.lag_s = params.lag_copter4_s if c4 else params.lag_apm25_s
        self.blind_s = params.blind_copter4_s if c4 else params.blind_apm25_s
        self._target_m: float | None = None
        self._arrived = False  # within band_m of the current target once
        self.rate_mps = 0.0  # the rate asked last tick (the ramp starts from it)
        # the vehicle's climb as the firmware follows the rates flown (a lag of lag_s): from
        # the commands, not the estimate, so no sonar noise in it
        self.model_vel_mps = 0.0
        self.open_loop_m = 0.0  # climb asked while the estimate was blind

    def engage(self, rate_mps: float = 0.0, vel_mps: float = 0.0) -> None:
        """Start from `rate_mps` with the vehicle climbing at `vel_mps` (from the floor: 0)."""
        self.rate_mps = rate_mps
        self.model_vel_mps = vel_mps
        self.open_loop_m = 0.0
        self._target_m = None
        self._arrived = False

    @property
    def blind_exhausted(self) -> bool:
        """The climb asked blind has carried the vehicle well past the blind band by now."""
        p = self.params
        return self.open_loop_m > p.blind_alt_m + p.blind_margin_m

    def update(self, target_m: float, estimate: AltEstimate, dt_s: float,
               speed_mps: float | None = None, *, blind: bool = False) -> ClimbRateOutput:
        """One step toward `target_m` (up, m). `blind`: the estimate cannot see the vehicle
        (below the rangefinder's minimum range): fly the move's rate open loop."""
        p = self.params
        alt = estimate.alt_m if estimate.control_alt_m is None else estimate.control_alt_m
        error = target_m - alt
        # where the vehicle would stop, centred now: the loop aims that at the target, so a
        # climb tapers before the lag would carry it past
        ahead = self.model_vel_mps * self.lag_s
        if target_m != self._target_m:  # a move (take-off, step, descent): not yet arrived
            self._target_m, self._arrived = target_m, False
        if abs(error) < p.band_m:
            self._arrived = True
        speed = p.speed_mps if speed_mps is None else speed_mps
        up = min(speed, self.stick.max_up_mps)
        down = min(speed, self.stick.max_down_mps)
        if blind and error > 0.0:
            want = up if not self.blind_exhausted else 0.0
        else:
            want = sqrt_shape(error - ahead, p.kp, p.decel_mps2)
            if self._arrived:
                up = min(up, max(0.0, (p.blind_room_m + error) / self.blind_s))
            want = min(up, max(-down, want))
        # speeding up is ramped; slowing down or turning back is not (the firmware brakes a
        # rate by its own shaping, and a late stop overshoots)
        prev = self.rate_mps
        if prev != 0.0 and (want > 0.0) != (prev > 0.0):
            prev = 0.0
        if abs(want) <= abs(prev):
            rate = want
        else:
            step = p.accel_mps2 * dt_s
            rate = prev + min(step, max(-step, want - prev))
        self.rate_mps = rate
        thr = self.stick.stick_us(rate)
        flown = self.stick.rate_mps(thr)
        self.model_vel_mps += dt_s / (self.lag_s + dt_s) * (flown - self.model_vel_mps)
        if blind:
            self.open_loop_m += max(rate, 0.0) * dt_s
        return ClimbRateOutput(target_m, alt, error, rate, flown, thr, blind)
