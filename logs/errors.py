"""The one error `logs/` raises for a recording a user handed in that cannot be used."""

from __future__ import annotations


class RecordingError(ValueError):
    """A recording is missing, not MCAP, truncated, or lacks what was asked of it."""
