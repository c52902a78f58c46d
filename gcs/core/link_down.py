"""How long the link has been down in all, counted on the loop's own ticks."""

from __future__ import annotations

from gcs.core.inputs import NEVER_S
from gcs.supervisor import LinkHealth


class LinkDownClock:
    """Adds each lost tick's `dt`; the first lost tick also adds the silence that made the link
    "lost" (the frame age then), unless nothing was ever heard."""

    def __init__(self) -> None:
        self.total_s = 0.0
        self._last = LinkHealth.OK

    def update(self, link: LinkHealth, frame_age_s: float, dt_s: float) -> float:
        """Count one tick whose link health the supervisor judged `link`; the total so far."""
        if link is LinkHealth.LOST:
            first = self._last is not LinkHealth.LOST and frame_age_s < NEVER_S
            self.total_s += dt_s + (frame_age_s if first else 0.0)
        self._last = link
        return self.total_s
