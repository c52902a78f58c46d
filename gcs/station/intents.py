"""What other threads may ask of a station: intents, queued and applied at its next tick.

The supervisor decides what each one means in the state it finds the vehicle in (an arm is
refused before the pre-flight checks pass; a hold request from the floor is a take-off ...).
"""

from __future__ import annotations

import queue

from firmware_link.pwm import PWM_MAX_US, PWM_MIN_US
from firmware_link.records import FlightMode
from gcs.control.position_controller import PositionSetpoint
from gcs.supervisor import Intent, IntentKind

STICK_MIN_US, STICK_MAX_US = PWM_MIN_US, PWM_MAX_US


def _clamp_us(v: int) -> int:
    return max(STICK_MIN_US, min(STICK_MAX_US, int(v)))


class StationIntents:
    """The intent methods of `Station` (which owns `_intents`)."""

    _intents: queue.SimpleQueue[Intent]

    def _intent(self, intent: Intent) -> None:
        self._intents.put(intent)

    def request_arm(self, wait_s: float | None = None) -> None:
        """Ask the vehicle to arm (refused by the supervisor until pre-flight checks pass),
        again each second for `wait_s` (None: the supervisor's arm_timeout_s, a few seconds)."""
        self._intent(Intent(IntentKind.ARM, wait_s=wait_s))

    def request_disarm(self) -> None:
        """Ask the vehicle to disarm."""
        self._intent(Intent(IntentKind.DISARM))

    def set_mode(self, mode: FlightMode) -> None:
        """Ask the vehicle for a flight mode (SET_MODE)."""
        self._intent(Intent(IntentKind.SET_MODE, mode=int(mode)))

    def set_sticks(self, roll_us: int, pitch_us: int, yaw_us: int, throttle_us: int) -> None:
        """Teleop sticks (µs); the throttle is used only under the pilot's control."""
        self._intent(Intent(IntentKind.STICKS, roll_us=_clamp_us(roll_us),
                            pitch_us=_clamp_us(pitch_us), throttle_us=_clamp_us(throttle_us),
                            yaw_us=_clamp_us(yaw_us)))

    def alt_hold(self, on: bool, setpoint_m: float | None = None,
                 rate_mps: float | None = None) -> None:
        """Engage PC altitude hold (taking off if on the floor) or leave it. The setpoint moves
        to `setpoint_m` at `rate_mps` (None: the controller's own profile); None keeps the
        present altitude."""
        self._intent(Intent(IntentKind.ALT_HOLD, setpoint_m=setpoint_m, rate_mps=rate_mps)
                     if on else Intent(IntentKind.ALT_HOLD_OFF))

    def set_position_setpoint(self, setpoint: PositionSetpoint | None) -> None:
        """Hold a mocap position while the altitude is held; None: level sticks from the pilot."""
        self._intent(Intent(IntentKind.POSITION_OFF) if setpoint is None else Intent(
            IntentKind.POSITION, north_m=setpoint.north_m, east_m=setpoint.east_m,
            yaw_rad=setpoint.yaw_rad))

    def kill(self) -> None:
        """Throttle to minimum from the next tick and disarm until a heartbeat says disarmed."""
        self._intent(Intent(IntentKind.KILL))

    def quit(self) -> None:
        """Land if flying (LAND confirmed by a heartbeat), then release the overrides."""
        self._intent(Intent(IntentKind.QUIT))

    def preflight(self, ok: bool, note: str) -> None:
        """The pre-flight checks' verdict: arming is refused until one says ok."""
        self._intent(Intent(IntentKind.PREFLIGHT, ok=ok, note=note))

