"""RTL and SmartRTL, vertically: what height the vehicle flies at while it returns and lands.

Both firmwares' RTL (`rtl_climb_start` … `rtl_land_run`; 4.x ModeRTL): climb to RTL_ALT (cm
above home) when below it — RTL_ALT 0, or already higher, returns at the current height —
at WPNAV_SPEED_UP; fly home at WPNAV_SPEED; loiter RTL_LOIT_TIME over home; then land
(RTL_ALT_FINAL 0): WPNAV_SPEED_DN above 10 m (3.2.1 LAND_START_ALT, 4.x LAND_ALT_LOW), LAND_SPEED
below. A landed, armed vehicle sent to RTL takes off again for the climb (measured on 3.2.1).
SmartRTL (4.x) retraces its path at the current height, then lands the same way, no loiter.
The horizontal leg is a wait of home distance / WPNAV_SPEED: the SITL flies no position.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

LAND_LOW_ALT_CM = 1000.0  # 3.2.1 LAND_START_ALT, 4.x LAND_ALT_LOW default
CLIMB_DONE_CM = 20.0  # close enough to the return height to turn for home
CLIMB_GAIN = 1.0  # 1/s: the climb slows over its last metres instead of overshooting


class RtlPhase(enum.Enum):
    """Where in its return the vehicle is."""

    CLIMB = "climb"
    RETURN = "return"
    LOITER = "loiter"
    LAND = "land"


@dataclass(frozen=True)
class RtlParams:
    """The parameters RTL reads (firmware units: cm, cm/s, ms)."""

    rtl_alt_cm: float
    loiter_ms: float
    speed_cms: float
    speed_up_cms: float
    speed_dn_cms: float
    land_speed_cms: float
    home_distance_m: float


@dataclass
class Rtl:
    """The vertical plan of one RTL or SmartRTL, advanced with the vehicle's height and time."""

    phase: RtlPhase = RtlPhase.LAND
    target_alt_cm: float = 0.0
    smart: bool = False
    _phase_end_s: float = 0.0

    def start(self, alt_cm: float, t_s: float, p: RtlParams, smart: bool) -> None:
        """Enter RTL (or SmartRTL) at height `alt_cm` above home."""
        self.smart = smart
        if smart or p.rtl_alt_cm <= 0.0 or alt_cm >= p.rtl_alt_cm:
            self.target_alt_cm = alt_cm
        else:
            self.target_alt_cm = p.rtl_alt_cm
        self.phase = RtlPhase.CLIMB
        self._phase_end_s = t_s

    @property
    def landing(self) -> bool:
        """In the final descent: touching down ends it as LAND's touchdown does."""
        return self.phase is RtlPhase.LAND

    def climb_rate(self, alt_cm: float, t_s: float, p: RtlParams) -> float:
        """Desired climb rate, cm/s, advancing the phase when its condition is met."""
        if self.phase is RtlPhase.CLIMB:
            error = self.target_alt_cm - alt_cm
            if error > CLIMB_DONE_CM:
                return min(p.speed_up_cms, max(p.land_speed_cms, error * CLIMB_GAIN))
            self.phase = RtlPhase.RETURN
            speed_ms = max(p.speed_cms, 1.0) / 100.0
            self._phase_end_s = t_s + p.home_distance_m / speed_ms
        if self.phase is RtlPhase.RETURN:
            if t_s < self._phase_end_s:
                return 0.0
            self.phase = RtlPhase.LOITER
            self._phase_end_s = t_s + (0.0 if self.smart else p.loiter_ms / 1000.0)
        if self.phase is RtlPhase.LOITER:
            if t_s < self._phase_end_s:
                return 0.0
            self.phase = RtlPhase.LAND
        return -(p.speed_dn_cms if alt_cm > LAND_LOW_ALT_CM else p.land_speed_cms)
