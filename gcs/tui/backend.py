"""The interface between the teleop screen and whatever feeds it (a live station or a replay)."""

from __future__ import annotations

from typing import Protocol

from gcs.pilot.intents import Intent
from gcs.pilot.view import TeleopView


class TeleopBackend(Protocol):
    """A source of views and a sink for intents; must never block the UI thread."""

    live: bool

    def view(self) -> TeleopView:
        """The latest state, cheap to call at the redraw rate."""
        ...

    def send(self, intent: Intent) -> None:
        """Hand an intent over; it is carried out on the backend's own thread."""
        ...

    def close(self) -> None:
        """Stop feeding: release overrides, stop threads, close files."""
        ...
