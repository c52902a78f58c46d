"""ArduCopter "+" frame mixer: motor 1 right, 2 left, 3 front, 4 back."""

from __future__ import annotations

from sitl.tick_record import tick_record

# (roll, pitch, yaw) factors from AP_MotorsMatrix: roll = cos(angle+90°), pitch = cos(angle),
# yaw +1 for the counter-clockwise props (1, 2), -1 for the clockwise ones (3, 4).
PLUS_FACTORS: tuple[tuple[float, float, float], ...] = (
    (-1.0, 0.0, 1.0),  # motor 1, right, CCW
    (1.0, 0.0, 1.0),  # motor 2, left, CCW
    (0.0, 1.0, -1.0),  # motor 3, front, CW
    (0.0, -1.0, -1.0),  # motor 4, back, CW
)

# Index of motors 1..4 in the physics order (front, right, back, left).
PHYSICS_ORDER: tuple[int, int, int, int] = (2, 0, 3, 1)


@tick_record
class MixerOutput:
    """Motor outputs 0..1 in ArduCopter order (1 right, 2 left, 3 front, 4 back)."""

    motors: tuple[float, float, float, float]
    limit_high: bool
    limit_low: bool

    def physics_order(self) -> tuple[float, float, float, float]:
        """The same outputs ordered (front, right, back, left) for the vehicle model."""
        m = self.motors
        return (m[2], m[0], m[3], m[1])

    def pwm_us(self) -> tuple[int, int, int, int]:
        """Outputs as ESC pulse widths, 1000..2000 µs."""
        a, b, c, d = (round(1000.0 + 1000.0 * x) for x in self.motors)
        return (a, b, c, d)


def mix_plus(
    throttle: float, roll: float, pitch: float, yaw: float, spin_min: float
) -> MixerOutput:
    """Mix normalised attitude demands (±1) onto four motors around `throttle` (0..1).

    Attitude is given priority over throttle, as AP_MotorsMatrix does: when a motor would pass
    full output the whole set is shifted down, and up when one would fall below `spin_min`.
    """
    deltas = [0.5 * (roll * fr + pitch * fp + yaw * fy) for fr, fp, fy in PLUS_FACTORS]
    hi = max(deltas)
    lo = min(deltas)
    thr = throttle
    limit_high = limit_low = False
    if thr + hi > 1.0:
        thr = 1.0 - hi
        limit_high = True
    if thr + lo < spin_min:
        thr = spin_min - lo
        limit_low = True
    out = []
    for d in deltas:  # min(1.0, max(spin_min, thr + d)) without the calls (same result)
        m = thr + d
        m = m if m > spin_min else spin_min
        out.append(m if m < 1.0 else 1.0)
    return MixerOutput((out[0], out[1], out[2], out[3]), limit_high, limit_low)
