"""ArduCopter's ALT_HOLD throttle stick: stick PWM → pilot climb rate, and its inverse.

In ALT_HOLD the throttle stick is a climb-rate request (`get_pilot_desired_climb_rate`), with a
dead zone about mid-stick in which the vehicle holds its height. The map, per firmware, in its
own integer arithmetic (ArduCopter's sources; the fixtures' `althold-steps` tlogs measure it):
- 4.x: the throttle's control_in is 1000 × (pwm − RC3_MIN − RC3_DZ) / (RC3_MAX − RC3_MIN −
  RC3_DZ), truncated; mid-stick is the same map of the stick's middle (484 with RC3_DZ 30), and
  THR_DZ about it is the dead zone (384..584: 1403–1597 µs). Above it PILOT_SPEED_UP × (c − top)
  / (1000 − top), below it PILOT_SPEED_DN (0: the up speed) × (c − bottom) / bottom.
- 3.2.1: control_in runs over THR_MIN..1000 (THR_MIN + (1000 − THR_MIN) × (pwm − 1000 − RC3_DZ)
  / (1000 − RC3_DZ), at least THR_MIN), the dead zone is 500 ± THR_DZ (1331–1554 µs), and both
  sides are PILOT_VELZ_MAX × (c − edge) / (500 − THR_DZ), in whole cm/s: the stick's bottom
  sinks at only 1.69 m/s.

The station inverts it over every whole microsecond, so a climb rate becomes the stick the
firmware turns into the nearest rate it can make, and a rate nearer zero than the smallest it
makes becomes mid-stick: "hold this height", the safest command to be flown blind.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

from firmware_link.records import Dialect

RC_MIN_US = 1000  # RC3_MIN / RC3_MAX: both firmwares' defaults
RC_MAX_US = 2000
MID_US = (RC_MIN_US + RC_MAX_US) // 2

CLIMB_PARAMS: dict[Dialect, tuple[str, ...]] = {
    Dialect.APM25: ("THR_MIN", "THR_DZ", "RC3_DZ", "PILOT_VELZ_MAX"),
    Dialect.COPTER4: ("THR_DZ", "RC3_DZ", "PILOT_SPEED_UP", "PILOT_SPEED_DN"),
}
"""The vehicle's parameters the map depends on, per dialect (read at connect)."""


def _trunc_div(a: int, b: int) -> int:
    """C's integer division (toward zero)."""
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b > 0) else -q


@dataclass(frozen=True, slots=True)
class ClimbStickMap:
    """One firmware's ALT_HOLD stick map with the vehicle's parameters (cm/s as they are set)."""

    dialect: Dialect = Dialect.APM25
    rc_dz_us: int = 30  # RC3_DZ
    thr_dz: int = 100  # THR_DZ, 0..1000 scale
    thr_min: int = 130  # 3.2.1 THR_MIN
    speed_up_cms: float = 250.0  # 4.x PILOT_SPEED_UP, 3.2.1 PILOT_VELZ_MAX
    speed_dn_cms: float = 0.0  # 4.x PILOT_SPEED_DN (0: the up speed)
    _rates: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not 0 <= self.rc_dz_us < 200 or not 0 <= self.thr_dz <= 400:
            raise ValueError(f"need 0 <= RC3_DZ < 200 and 0 <= THR_DZ <= 400, got "
                             f"{self.rc_dz_us}, {self.thr_dz}")
        if self.speed_up_cms <= 0.0 or self.speed_dn_cms < 0.0:
            raise ValueError("the pilot's climb speed must be > 0 (the sink speed >= 0)")
        rates = tuple(self._rate_cms(pwm) / 100.0 for pwm in range(RC_MIN_US, RC_MAX_US + 1))
        object.__setattr__(self, "_rates", rates)

    @staticmethod
    def for_dialect(dialect: Dialect, params: dict[str, float] | None = None) -> ClimbStickMap:
        """The map for a firmware, with the vehicle's parameters where known."""
        p = params or {}
        rc_dz, thr_dz = round(p.get("RC3_DZ", 30.0)), round(p.get("THR_DZ", 100.0))
        if dialect is Dialect.COPTER4:
            return ClimbStickMap(dialect, rc_dz, thr_dz,
                                 speed_up_cms=p.get("PILOT_SPEED_UP", 250.0),
                                 speed_dn_cms=p.get("PILOT_SPEED_DN", 0.0))
        return ClimbStickMap(Dialect.APM25, rc_dz, thr_dz,
                             thr_min=round(p.get("THR_MIN", 130.0)),
                             speed_up_cms=p.get("PILOT_VELZ_MAX", 250.0))

    # ------------------------------------------------------------------ the firmware's map
    def _control_in(self, pwm: int) -> int:
        r = min(RC_MAX_US, max(RC_MIN_US, pwm))
        low = RC_MIN_US + self.rc_dz_us
        if self.dialect is Dialect.COPTER4:
            return 0 if r <= low else _trunc_div(1000 * (r - low), RC_MAX_US - low)
        c = 0 if r <= low else self.thr_min + _trunc_div((1000 - self.thr_min) * (r - low),
                                                           RC_MAX_US - low)
        return min(1000, max(self.thr_min, c))

    def _rate_cms(self, pwm: int) -> float:
        c = self._control_in(pwm)
        if self.dialect is Dialect.COPTER4:
            mid = self._control_in(MID_US)
            top, bottom = mid + self.thr_dz, mid - self.thr_dz
            down = self.speed_dn_cms if self.speed_dn_cms > 0.0 else self.speed_up_cms
            if c < bottom:
                return down * (c - bottom) / bottom
            if c > top:
                return self.speed_up_cms * (c - top) / (1000.0 - top)
            return 0.0
        top, bottom = 500 + self.thr_dz, 500 - self.thr_dz
        vmax = round(self.speed_up_cms)
        if c < bottom:
            return float(_trunc_div(vmax * (c - bottom), 500 - self.thr_dz))
        if c > top:
            return float(_trunc_div(vmax * (c - top), 500 - self.thr_dz))
        return 0.0

    # ------------------------------------------------------------------ the station's use
    def rate_mps(self, pwm_us: int) -> float:
        """The climb rate (m/s, up) the firmware makes of a stick PWM."""
        return self._rates[min(RC_MAX_US, max(RC_MIN_US, pwm_us)) - RC_MIN_US]

    @property
    def dead_zone_us(self) -> tuple[int, int]:
        """The lowest and highest stick PWM that hold the height."""
        zero = [pwm for pwm in range(RC_MIN_US, RC_MAX_US + 1) if self.rate_mps(pwm) == 0.0]
        return zero[0], zero[-1]

    @property
    def max_up_mps(self) -> float:
        return self._rates[-1]

    @property
    def max_down_mps(self) -> float:
        return -self._rates[0]

    def stick_us(self, rate_mps: float) -> int:
        """The stick whose rate is nearest `rate_mps` (clamped to what the stick can ask);
        mid-stick for a rate nearer zero than the smallest the firmware makes."""
        rates = self._rates
        i = bisect.bisect_left(rates, rate_mps)
        best = min((j for j in (i - 1, i) if 0 <= j < len(rates)),
                   key=lambda j: abs(rates[j] - rate_mps))
        if rates[best] == 0.0:
            return MID_US
        # several microseconds may make the same rate: the one nearest mid-stick, so a stick a
        # microsecond off (a receiver's jitter) stays on the same side of the dead zone
        same = rates[best]
        lo = bisect.bisect_left(rates, same)
        hi = bisect.bisect_right(rates, same) - 1
        return RC_MIN_US + (hi if same < 0.0 else lo)
