"""GCS, radio and battery failsafe timers (pure: time passed in). What a failsafe then does is
in `failsafe_rules.py`.

- GCS failsafe: 3.2.1 fires 5 s (fixed FS_GCS_TIMEOUT_MS) after the last GCS heartbeat or RC
  override (both reset the timer), only while overrides are in use and armed; 4.x fires
  FS_GCS_TIMEOUT after the last heartbeat or override from MAV_GCS_SYSID once the GCS has been
  seen, armed or not (disarmed it only announces). Only when FS_GCS_ENABLE is not 0 (4.x's
  default is 0: no GCS failsafe).
- Radio failsafe (FS_THR_ENABLE) with no RC receiver: the only radio input is the GCS's
  overrides, so `read_radio()` sees no new frame RC_FS_TIMEOUT (4.x, 1 s) or
  FAILSAFE_RADIO_TIMEOUT_MS (3.2.1, 2 s) after the last override. With a receiver whose
  throttle stays above FS_THR_VALUE (975 µs) it never fires. A vehicle without overrides ever
  has no input to lose.
"""

from __future__ import annotations

from dataclasses import dataclass

GCS_TIMEOUT_S = 5.0  # 3.2.1's fixed FS_GCS_TIMEOUT_MS; 4.x's FS_GCS_TIMEOUT default
BATT_LOW_TIMER_S = 10.0  # voltage must stay low this long (BATT_LOW_TIMER)


@dataclass
class GcsWatch:
    """When the GCS was last heard (heartbeat or override from the GCS system id)."""

    last_seen_s: float | None = None
    active: bool = False

    def seen(self, t_s: float) -> None:
        """Record GCS traffic."""
        self.last_seen_s = t_s

    def check(
        self,
        t_s: float,
        requires_override: bool,
        override_active: bool,
        timeout_s: float = GCS_TIMEOUT_S,
    ) -> bool | None:
        """Return True on the tick the failsafe starts, False on the tick it ends, else None.

        3.2.1 only arms this failsafe once the GCS has been overriding the sticks
        (`requires_override`); 4.x needs only that the GCS was ever seen.
        """
        if self.last_seen_s is None:
            return None
        silent = t_s - self.last_seen_s > timeout_s
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
class RadioWatch:
    """The radio failsafe with no receiver: new radio input comes only from overrides."""

    last_input_s: float | None = None
    active: bool = False

    def input(self, t_s: float) -> None:
        """An override arrived (a new radio frame as far as `read_radio()` is concerned)."""
        self.last_input_s = t_s

    def check(self, t_s: float, armed: bool, timeout_s: float) -> bool | None:
        """True on the tick the failsafe starts, False when input returns, else None."""
        if self.last_input_s is None:
            return None
        late = t_s - self.last_input_s >= timeout_s
        if late and not self.active and armed:
            self.active = True
            return True
        if not late and self.active:
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
