"""ArduCopter's manual throttle curves (stick PWM → motor throttle) and their inverses.

In STABILIZE the throttle stick is not the motor command: the firmware passes it through a curve
so that mid-stick is near hover. To command a thrust, the station inverts that curve.
- APM 2.5 / ArduCopter 3.2.1 (`get_pilot_desired_throttle`): piecewise linear, stick 0..500 maps
  THR_MIN→THR_MID (extended linearly below THR_MIN), stick 500..1000 maps THR_MID→1000; all on
  the 0..1000 throttle scale.
- ArduCopter 4.x: the stick (0..1) is made piecewise linear around mid-stick, then an expo
  out = in·(1−e) + e·in³ with e = clamp(−(hover − 0.5)/0.375, −0.5, 1) puts MOT_THST_HOVER at
  mid-stick.
Motor thrust is taken as proportional to the motor throttle: ArduCopter's thrust linearisation
(MOT_THST_EXPO) exists to make that so, and the measured real firmware agrees (+25 µs ≈
+0.61 m/s² from hover with MOT_THST_HOVER 0.39, the expo slope predicts +0.58 m/s²).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from firmware_link.records import Dialect


class CurveKind(enum.Enum):
    """Which firmware's manual throttle curve."""

    APM25 = "apm25"
    COPTER4 = "copter4"


@dataclass(frozen=True, slots=True)
class ThrottleCurve:
    """Stick PWM ↔ motor throttle (0..1) for one firmware, with its parameters."""

    kind: CurveKind = CurveKind.APM25
    rc_min_us: int = 1000
    rc_max_us: int = 2000
    thr_min: float = 130.0  # 3.2.1 THR_MIN, 0..1000 scale
    thr_mid: float = 500.0  # 3.2.1 THR_MID, 0..1000 scale
    thst_hover: float = 0.39  # 4.x MOT_THST_HOVER, 0..1

    def __post_init__(self) -> None:
        if self.rc_max_us <= self.rc_min_us:
            raise ValueError("rc_max_us must exceed rc_min_us")
        if not 0.0 <= self.thr_min < self.thr_mid < 1000.0:
            raise ValueError(
                f"need 0 <= THR_MIN < THR_MID < 1000, got {self.thr_min}, {self.thr_mid}"
            )
        if not 0.0 < self.thst_hover < 1.0:
            raise ValueError(f"MOT_THST_HOVER must be in (0, 1), got {self.thst_hover}")

    @staticmethod
    def for_dialect(dialect: Dialect, params: dict[str, float] | None = None) -> ThrottleCurve:
        """The curve for a firmware, with the vehicle's parameters where known."""
        p = params or {}
        if dialect is Dialect.COPTER4:
            return ThrottleCurve(CurveKind.COPTER4, thst_hover=p.get("MOT_THST_HOVER", 0.39))
        return ThrottleCurve(
            CurveKind.APM25, thr_min=p.get("THR_MIN", 130.0), thr_mid=p.get("THR_MID", 500.0)
        )

    @property
    def _mid(self) -> float:
        # ArduCopter 3.2.1 constrains THR_MID to 300..700 before using it
        return min(max(self.thr_mid, 300.0), 700.0)

    @property
    def mid_output(self) -> float:
        """Motor throttle at mid-stick (the firmware's own hover guess), 0..1."""
        return self.output(0.5 * (self.rc_min_us + self.rc_max_us))

    def _stick(self, pwm_us: float) -> float:
        x = (pwm_us - self.rc_min_us) / (self.rc_max_us - self.rc_min_us)
        return min(max(x, 0.0), 1.0)

    def output(self, pwm_us: float) -> float:
        """Motor throttle 0..1 the firmware makes of a stick PWM."""
        s = self._stick(pwm_us)
        if self.kind is CurveKind.APM25:
            c = s * 1000.0
            mid = self._mid
            if c < 500.0:
                out = self.thr_min + (c - self.thr_min) * (mid - self.thr_min) / (
                    500.0 - self.thr_min
                )
            else:
                out = mid + (c - 500.0) * (1000.0 - mid) / 500.0
            return min(max(out / 1000.0, 0.0), 1.0)
        e = self._expo()
        return s * (1.0 - e) + e * s**3

    def _expo(self) -> float:
        return min(max(-(self.thst_hover - 0.5) / 0.375, -0.5), 1.0)

    def stick_us(self, output: float) -> float:
        """The stick PWM that makes motor throttle `output` (clamped to the stick's range)."""
        lo, hi = self.output(self.rc_min_us), self.output(self.rc_max_us)
        out = min(max(output, lo), hi)
        span = self.rc_max_us - self.rc_min_us
        if self.kind is CurveKind.APM25:
            o = out * 1000.0
            mid, lo = self._mid, self.thr_min
            if o < mid:
                c = lo + (o - lo) * (500.0 - lo) / (mid - lo)
            else:
                c = 500.0 + (o - mid) * 500.0 / (1000.0 - mid)
            return self.rc_min_us + min(max(c / 1000.0, 0.0), 1.0) * span
        # the expo is monotonic on [0, 1] for e in [-0.5, 1]: bisection is exact enough in 40 steps
        a, b = 0.0, 1.0
        for _ in range(40):
            m = 0.5 * (a + b)
            if self.output(self.rc_min_us + m * span) < out:
                a = m
            else:
                b = m
        return self.rc_min_us + 0.5 * (a + b) * span
