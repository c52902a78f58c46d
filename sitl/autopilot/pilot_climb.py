"""ALT_HOLD's pilot climb rate from the throttle channel, in each firmware's integer arithmetic.

The dead zones and rates this gives are the fixtures' (`althold-steps`, fixtures/README.md):
- 4.x: control_in = 1000 × (pwm − RC3_MIN − RC3_DZ) / (RC3_MAX − RC3_MIN − RC3_DZ), truncated;
  the stick's middle is the same map of (RC3_MIN + RC3_MAX) / 2 (484 with RC3_DZ 30), so THR_DZ
  100 gives a dead zone of 384..584: 1403–1597 µs (measured ≈ 1403–1597). Above it
  PILOT_SPEED_UP × (c − 584) / (1000 − 584); below it PILOT_SPEED_DN (0: the up speed)
  × (c − 384) / 384: 1700 µs +64 cm/s, 1300 µs −69 cm/s (measured +63, −68).
- 3.2.1: the throttle channel's range is THR_MIN..THR_MAX, so control_in = THR_MIN + (1000 −
  THR_MIN) × (pwm − 1000 − RC3_DZ) / (1000 − RC3_DZ), and anything lower reads THR_MIN: the dead
  zone 400..600 is 1331–1554 µs (measured ≈ 1335–1553). Both sides divide by (500 − THR_DZ):
  PILOT_VELZ_MAX × (c − 600) / 400 up, × (c − 400) / 400 down; so the stick's bottom (c 130)
  sinks at only 169 cm/s and 1300 µs at 17 cm/s (measured 15, still settling).
"""

from __future__ import annotations

RC_MIN_US = 1000  # RC3_MIN / RC3_MAX of both firmwares' defaults, and this SITL's radio
RC_MAX_US = 2000
MID_STICK = 500


def _trunc_div(a: int, b: int) -> int:
    """C's integer division (toward zero)."""
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b > 0) else -q


def control_in_copter4(pwm: int, rc_dz: int) -> int:
    """RC_Channel::pwm_to_range_dz for the throttle (0..1000)."""
    r = min(RC_MAX_US, max(RC_MIN_US, pwm))
    low = RC_MIN_US + rc_dz
    if r <= low:
        return 0
    return _trunc_div(1000 * (r - low), RC_MAX_US - low)


def climb_rate_copter4(
    pwm: int, rc_dz: int, thr_dz: int, speed_up_cms: float, speed_dn_cms: float
) -> float:
    """4.x get_pilot_desired_climb_rate, cm/s up."""
    c = control_in_copter4(pwm, rc_dz)
    mid = control_in_copter4((RC_MIN_US + RC_MAX_US) // 2, rc_dz)
    dz = min(400, max(0, thr_dz))
    top, bottom = mid + dz, mid - dz
    down = speed_dn_cms if speed_dn_cms > 0 else speed_up_cms
    if c < bottom:
        return down * (c - bottom) / bottom
    if c > top:
        return speed_up_cms * (c - top) / (1000.0 - top)
    return 0.0


def control_in_apm25(pwm: int, rc_dz: int, thr_min: int, thr_max: int = 1000) -> int:
    """3.2.1's throttle control_in over its THR_MIN..THR_MAX range; 0 inside the bottom dead
    zone, which get_pilot_desired_climb_rate then raises to THR_MIN."""
    r = min(RC_MAX_US, max(RC_MIN_US, pwm))
    low = RC_MIN_US + rc_dz
    if r <= low:
        return 0
    return thr_min + _trunc_div((thr_max - thr_min) * (r - low), RC_MAX_US - low)


def climb_rate_apm25(pwm: int, rc_dz: int, thr_dz: int, thr_min: int, velz_max_cms: int) -> float:
    """3.2.1 get_pilot_desired_climb_rate, cm/s up (integer, as the firmware)."""
    c = min(1000, max(thr_min, control_in_apm25(pwm, rc_dz, thr_min)))
    dz = min(400, max(0, thr_dz))
    top, bottom = MID_STICK + dz, MID_STICK - dz
    if c < bottom:
        return float(_trunc_div(velz_max_cms * (c - bottom), MID_STICK - dz))
    if c > top:
        return float(_trunc_div(velz_max_cms * (c - top), MID_STICK - dz))
    return 0.0
