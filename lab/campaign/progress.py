"""The campaign's progress line: runs done, failed, the rate and the time still to go."""

from __future__ import annotations

import sys
import time
from typing import TextIO


def _clock(seconds: float) -> str:
    s = round(seconds)
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


class Progress:
    """Rewrites one line on a terminal; elsewhere prints a line every `every_s` seconds."""

    def __init__(self, total: int, skipped: int = 0, stream: TextIO | None = None,
                 every_s: float = 10.0, quiet: bool = False) -> None:
        self.total = total
        self.skipped = skipped
        self.done = 0
        self.failed = 0
        self._stream = stream or sys.stderr
        self._tty = self._stream.isatty()
        self._every_s = every_s
        self._quiet = quiet
        self._t0 = time.monotonic()
        self._last = -1e9

    def line(self) -> str:
        """The line as it stands."""
        elapsed = time.monotonic() - self._t0
        rate = self.done / elapsed if elapsed > 0 else 0.0
        left = self.total - self.skipped - self.done
        eta = _clock(left / rate) if rate > 0 else "?"
        bar_n = 20
        filled = int(bar_n * (self.skipped + self.done) / max(1, self.total))
        skipped = f", {self.skipped} already done" if self.skipped else ""
        return (f"[{'#' * filled}{'.' * (bar_n - filled)}] {self.skipped + self.done}/"
                f"{self.total} runs{skipped}, {self.failed} failed, {rate * 60:.0f} runs/min, "
                f"ETA {eta}")

    def update(self, ok: bool) -> None:
        """One more run finished."""
        self.done += 1
        self.failed += not ok
        self.show()

    def show(self, final: bool = False) -> None:
        """Print (or rewrite) the line when it is due."""
        if self._quiet:
            return
        now = time.monotonic()
        if not final and not self._tty and now - self._last < self._every_s:
            return
        self._last = now
        end = "\n" if final or not self._tty else ""
        print(("\r" if self._tty else "") + self.line(), end=end, file=self._stream, flush=True)
