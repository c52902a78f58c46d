"""Lift-off felt by the accelerometer while the take-off ramp raises the throttle.

Below its minimum range (RNGFND1_MIN 0.2 m on 4.x, RNGFND_MIN_CM 20 on 3.2.1) the rangefinder
says nothing a take-off can use, and a take-off that waited for the sonar to see the vehicle
rise saw it late: on the real 4.7 it left the floor at 1475 us and was seen 1.15 s later at
0.3 m and 1.3 m/s, with the ramp at 1590 us (12-36 % overshoot at 1 m). On the floor the
accelerometer reads no vertical acceleration whatever the throttle (the floor carries the
difference); the moment thrust exceeds weight it reads the difference. So lift-off is:

- the bias-corrected upward acceleration, averaged over `accel_tc_s` (the rotors' vibration is
  ~0.5 m/s² a sample), above `accel_mps2`;
- the velocity it integrates since the ramp began, never below 0 (the floor stops a fall) and
  leaking over `leak_s` (so that vibration does not add up over a long ramp), above
  `rise_mps`: a climb, not a knock;
- at a throttle whose own acceleration, by the curve and the hover the station assumes, is
  above `min_expected_mps2`: a ramp far below hover cannot lift the vehicle, whatever a knock
  on the floor reads (the margin is wide, as the hover assumed can be wrong: 3.2.1's THR_MID
  stands for 1500 us against the real vehicle's 1370).

Pure: the caller passes the tick's reading and `dt_s`.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class LiftoffParams:
    """When the accelerometer says the vehicle has left the floor (see the module)."""

    accel_tc_s: float = 0.1
    accel_mps2: float = 0.4
    rise_mps: float = 0.12
    leak_s: float = 1.0
    min_expected_mps2: float = -2.5

    def __post_init__(self) -> None:
        if min(self.accel_tc_s, self.accel_mps2, self.rise_mps, self.leak_s) <= 0.0:
            raise ValueError("accel_tc_s, accel_mps2, rise_mps and leak_s must be > 0")


class LiftoffDetector:
    """The accelerometer's view of a take-off ramp (see the module)."""

    def __init__(self, params: LiftoffParams | None = None) -> None:
        self.params = params or LiftoffParams()
        self.acc_mps2 = 0.0  # averaged upward acceleration
        self.vel_mps = 0.0  # integrated since the ramp began, >= 0, leaking

    def reset(self) -> None:
        """A new ramp: standing on the floor."""
        self.acc_mps2 = 0.0
        self.vel_mps = 0.0

    def update(self, acc_up_mps2: float, expected_mps2: float, dt_s: float) -> bool:
        """One tick: the estimator's bias-corrected upward acceleration, the acceleration the
        throttle sent asks for (relative to the assumed hover). Whether the vehicle has left
        the floor."""
        p = self.params
        if dt_s <= 0.0:
            return False
        self.acc_mps2 += (acc_up_mps2 - self.acc_mps2) * dt_s / (p.accel_tc_s + dt_s)
        self.vel_mps = max(0.0, self.vel_mps + (acc_up_mps2 - self.vel_mps / p.leak_s) * dt_s)
        return (expected_mps2 > p.min_expected_mps2 and self.acc_mps2 > p.accel_mps2
                and self.vel_mps > p.rise_mps)

    @property
    def rise_m(self) -> float:
        """How high the vehicle is by now, had it accelerated evenly from rest at the averaged
        acceleration to the integrated speed (integrating the speed again would add up the
        floor's vibration over the whole ramp: 17 cm "risen" with the vehicle at 1 cm)."""
        return self.vel_mps**2 / (2.0 * max(self.acc_mps2, self.params.accel_mps2))
