"""Radio input with GCS overrides, per each firmware's RC_CHANNELS_OVERRIDE rules.

With a receiver (`RcInput.MIN` / `MID`) a channel no override holds reads the receiver: sticks
centred, switches low, the throttle at 1000 or 1500 µs. Without one (`ABSENT`) nothing updates a
channel once its override ends, so it keeps the last value flown (both firmwares keep
`radio_in` when no new frame arrives; 4.x `RC_Channel::update` returns without touching it).
"""

from __future__ import annotations

from collections.abc import Sequence

from sitl.autopilot.profile import Profile, RcInput

UINT16_MAX = 65535
N_CHANNELS = 8
RADIO_MIN_US = 1000
RADIO_MAX_US = 2000
# The simulated transmitter: sticks at trim, throttle at the bottom, switches low.
RADIO_IDLE_US: tuple[int, ...] = (1500, 1500, 1000, 1500, 1000, 1000, 1000, 1000)


class Radio:
    """Channel values the autopilot sees: the radio's, unless a GCS override holds a channel."""

    def __init__(self, profile: Profile, rc_input: RcInput = RcInput.MIN) -> None:
        self.profile = profile
        self.rc_input = rc_input
        self.radio_us = list(RADIO_IDLE_US)
        if rc_input is RcInput.MID:
            self.radio_us[2] = 1500
        self._override: list[int] = [0] * N_CHANNELS
        self._override_t_s: list[float] = [0.0] * N_CHANNELS

    def apply_override(self, values: Sequence[int], t_s: float) -> None:
        """Apply one RC_CHANNELS_OVERRIDE (channels 1–8): 0 releases, 65535 leaves alone."""
        for i, v in enumerate(values[:N_CHANNELS]):
            if v == UINT16_MAX:
                continue
            if v == 0:
                self._override[i] = 0
                continue
            self._override[i] = min(RADIO_MAX_US, max(RADIO_MIN_US, int(v)))
            self._override_t_s[i] = t_s
            if self.rc_input is RcInput.ABSENT:
                self.radio_us[i] = self._override[i]  # what the channel keeps once it ends

    def clear_overrides(self) -> None:
        """Drop every override (GCS failsafe)."""
        self._override = [0] * N_CHANNELS

    def expire(self, t_s: float, timeout_s: float) -> bool:
        """Copter 4.x RC_OVERRIDE_TIME: drop overrides older than `timeout_s`; True if any did."""
        if timeout_s <= 0.0:
            return False
        dropped = False
        for i in range(N_CHANNELS):
            if self._override[i] and t_s - self._override_t_s[i] >= timeout_s:
                self._override[i] = 0
                dropped = True
        return dropped

    @property
    def overridden(self) -> bool:
        """Whether any channel is overridden."""
        return any(self._override)

    def channel(self, index: int) -> int:
        """Current value of channel `index` (0-based), µs."""
        o = self._override[index]
        return o if o else self.radio_us[index]

    def channels(self) -> tuple[int, ...]:
        """All eight channels, µs."""
        return tuple(self.channel(i) for i in range(N_CHANNELS))
