"""Copter 4.x motor spool states after arming (AP_MotorsMulticopter::output_logic).

Measured on 4.7-dev SITL (fixture tlog, armed at 23.54 s): SERVO_OUTPUT_RAW stays at 1000 µs
(motors stopped) for 2 s whatever the throttle (Copter's ARMING_DELAY_SEC, `ap.in_arming_delay`),
then spools to MOT_SPIN_ARM (1100 µs) over MOT_SPOOL_TIME, and only from there ramps its thrust
limit from 0 to 1 over MOT_SPOOL_TIME once the pilot asks for throttle (THROTTLE_UNLIMITED).
Take-off in ALT_HOLD waits for the full spool (`takeoff.triggered` needs THROTTLE_UNLIMITED).
3.2.1 has none of this: its motors spin at MOT_SPIN_ARMED the moment it is armed, so its
`Spool` is built with no delay and no ramp.
"""

from __future__ import annotations

from dataclasses import dataclass

ARMING_DELAY_S = 2.0  # ArduCopter ARMING_DELAY_SEC


@dataclass
class Spool:
    """Ground-idle ratio (0 stopped .. 1 at MOT_SPIN_ARM) and thrust limit (0 .. 1)."""

    arming_delay_s: float = ARMING_DELAY_S
    armed_at_s: float | None = None
    idle_ratio: float = 0.0
    thrust_max: float = 0.0

    def arm(self, t_s: float) -> None:
        """Motors armed at `t_s`: stopped through the arming delay."""
        self.armed_at_s = t_s
        self.idle_ratio = 0.0
        self.thrust_max = 0.0

    def disarm(self) -> None:
        """Motors off."""
        self.armed_at_s = None
        self.idle_ratio = 0.0
        self.thrust_max = 0.0

    @property
    def unlimited(self) -> bool:
        """THROTTLE_UNLIMITED reached: the full thrust range is available."""
        return self.thrust_max >= 1.0

    def update(self, t_s: float, dt_s: float, spool_time_s: float, want_thrust: bool) -> None:
        """Advance the spool; `want_thrust`: the mode asks for more than ground idle."""
        if self.armed_at_s is None:
            return
        if t_s + 1e-9 < self.armed_at_s + self.arming_delay_s:
            return
        step = dt_s / spool_time_s if spool_time_s > 0.0 else 1.0
        if self.idle_ratio < 1.0:
            self.idle_ratio = min(1.0, self.idle_ratio + step)
            return
        if want_thrust:
            self.thrust_max = min(1.0, self.thrust_max + step)
        else:
            self.thrust_max = max(0.0, self.thrust_max - step)
