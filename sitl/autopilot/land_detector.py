"""Landing detector: throttle demand at its floor and no vertical motion for a second."""

from __future__ import annotations

from dataclasses import dataclass

LAND_DETECT_S = 1.0
CLIMB_MAX_MS = 0.4  # Copter 3.2.1 LAND_DETECTOR_CLIMBRATE_MAX 40 cm/s (4.x allows 1 m/s)


@dataclass
class LandDetector:
    """Keeps `landed` like ArduCopter's ap.land_complete."""

    landed: bool = True
    climb_max_ms: float = CLIMB_MAX_MS
    _still_s: float = 0.0

    def update(
        self, throttle_low: bool, climb_ms: float, throttle: float, hover: float, dt_s: float
    ) -> bool:
        """Advance; returns True on the tick touchdown is declared."""
        if self.landed:
            if throttle > 0.75 * hover:
                self.landed = False
                self._still_s = 0.0
            return False
        if throttle_low and abs(climb_ms) < self.climb_max_ms:
            self._still_s += dt_s
            if self._still_s >= LAND_DETECT_S:
                self.landed = True
                return True
        else:
            self._still_s = 0.0
        return False
