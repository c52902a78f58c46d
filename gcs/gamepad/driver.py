"""The pad as the teleop app sees it: read the device, step the pure core, hand back intents.

The app calls `poll` from a timer on its own (UI) thread at the mapping's `poll_hz`; the loop
runs in the station's process and never waits on a pad.
"""

from __future__ import annotations

from typing import Protocol

from gcs.gamepad.core import GamepadPilot, PadSample, PadStatus, VehicleState
from gcs.gamepad.mapping import PadMapping, PadSettings
from gcs.pilot import intents
from gcs.pilot.view import TeleopView


class PadSource(Protocol):
    """A device that reads as samples by role (SDL's, or a test's)."""

    name: str
    mapping: PadMapping
    settings: PadSettings

    def read(self) -> PadSample | None:
        """The pad's state now; None while unplugged."""
        ...

    def close(self) -> None:
        """Let the device go."""
        ...


def vehicle_state(view: TeleopView) -> VehicleState:
    """What the core needs to know of the vehicle, from the latest view."""
    return VehicleState(armed=view.vehicle.armed, hold_on=view.altitude.hold_on,
                        mode=view.vehicle.mode, throttle_us=view.altitude.throttle_us)


class Gamepad:
    """A pad and its core, polled by the app."""

    def __init__(self, source: PadSource) -> None:
        self.source = source
        self.pilot = GamepadPilot(source.settings)

    @property
    def name(self) -> str:
        """The pad's SDL name."""
        return self.source.name

    @property
    def poll_hz(self) -> float:
        """How often the app should call `poll`."""
        return self.source.settings.poll_hz

    @property
    def status(self) -> PadStatus:
        """What the pad did on the last poll, for the screen."""
        return self.pilot.status

    def poll(self, t_s: float, view: TeleopView) -> list[intents.Intent]:
        """Read the pad once and return what it asks for."""
        return self.pilot.step(t_s, self.source.read(), vehicle_state(view))

    def close(self) -> None:
        """Release the device."""
        self.source.close()
