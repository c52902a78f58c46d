"""GCS and battery failsafe timers (pure: time passed in)."""

from __future__ import annotations

import enum
from dataclasses import dataclass

GCS_TIMEOUT_S = 5.0  # FS_GCS_TIMEOUT of both firmwares
BATT_LOW_TIMER_S = 10.0  # voltage must stay low this long (BATT_LOW_TIMER)


class GcsFailsafeAction(enum.IntEnum):
    """FS_GCS_ENABLE values."""

    DISABLED = 0
    LAND = 1  # RTL in the firmware; without GPS it lands
    CONTINUE = 2  # 3.2.1: continue in AUTO (lands in other modes); 4.x: same as LAND here
    HOLD_THEN_LAND = 3  # this SITL's option: hold altitude, land on low battery


@dataclass
class GcsWatch:
    """When the GCS was last heard (heartbeat or override from SYSID_MYGCS)."""

    last_seen_s: float | None = None
    active: bool = False

    def seen(self, t_s: float) -> None:
        """Record GCS traffic."""
        self.last_seen_s = t_s

    def check(self, t_s: float, requires_override: bool, override_active: bool) -> bool | None:
        """Return True on the tick the failsafe starts, False on the tick it ends, else None.

        3.2.1 only arms this failsafe once the GCS has been overriding the sticks
        (`requires_override`); 4.x needs only that the GCS was ever seen.
        """
        if self.last_seen_s is None:
            return None
        silent = t_s - self.last_seen_s > GCS_TIMEOUT_S
        if silent and not self.active:
            if requires_override and not override_active:
                return None
            self.active = True
            return True
        if not silent and self.active:
            self.active = False
            return False
        return None


@dataclass
class BatteryWatch:
    """Low-voltage timer."""

    low_since_s: float | None = None
    triggered: bool = False

    def check(self, t_s: float, voltage_v: float, threshold_v: float) -> bool:
        """True once, when the voltage has been under `threshold_v` for BATT_LOW_TIMER_S."""
        if threshold_v <= 0.0 or self.triggered or voltage_v <= 0.0:
            return False
        if voltage_v >= threshold_v:
            self.low_since_s = None
            return False
        if self.low_since_s is None:
            self.low_since_s = t_s
        if t_s - self.low_since_s >= BATT_LOW_TIMER_S:
            self.triggered = True
            return True
        return False
