"""Play a recorded flight back on its own timeline, on an injectable clock.

`Player` is a pure scheduler: it never sleeps or starts threads. Whoever drives it (the headless
`quadgcs replay`, or the TUI's timer) asks `due()` for the messages whose recorded time has come
and `wait_s()` for how long until the next one. `play`, `pause`, `seek` and `speed` re-anchor the
mapping from clock time to recording time, so they take effect at once and never skip messages
between the last `due()` and the change.
"""

from __future__ import annotations

import bisect
import json
import math
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any, TextIO

from logs.errors import RecordingError
from logs.reader import Recording
from logs.signals import SignalTracker

Clock = Callable[[], float]


@dataclass(frozen=True, slots=True)
class ReplayMessage:
    """One message as played: topic, its recording-relative time, and its content."""

    topic: str
    t_s: float  # seconds since the recording's first message
    log_time_ns: int
    message: dict[str, Any]


class Player:
    """Plays a recording at `speed`× on `clock` (seconds, monotonic)."""

    def __init__(
        self,
        recording: Recording,
        *,
        topics: Iterable[str] | None = None,
        clock: Clock = time.monotonic,
        speed: float = 1.0,
    ) -> None:
        self._clock = clock
        json_topics = _json_topics(recording)
        raw = [
            (log_ns, topic, data)
            for topic, log_ns, data in recording.raw_messages(topics)
            if topic in json_topics
        ]
        self._times_ns = [r[0] for r in raw]
        self._items = raw
        self._start_ns = recording.start_ns if raw else 0
        self._duration_s = (raw[-1][0] - self._start_ns) / 1e9 if raw else 0.0
        self._index = 0
        self._speed = _check_speed(speed)
        self._playing = False
        self._anchor_clock = clock()
        self._anchor_pos_s = 0.0

    @property
    def duration_s(self) -> float:
        """Recording length, s."""
        return self._duration_s

    @property
    def playing(self) -> bool:
        """True between `play()` and `pause()`."""
        return self._playing

    @property
    def finished(self) -> bool:
        """True once every message has been handed out."""
        return self._index >= len(self._items)

    @property
    def position_s(self) -> float:
        """Current position on the recording's timeline, s from its first message."""
        if not self._playing:
            return self._anchor_pos_s
        pos = self._anchor_pos_s + (self._clock() - self._anchor_clock) * self._speed
        return min(pos, self._duration_s)

    @property
    def speed(self) -> float:
        """Playback rate (1 = as recorded)."""
        return self._speed

    @speed.setter
    def speed(self, value: float) -> None:
        self._reanchor()
        self._speed = _check_speed(value)

    def _reanchor(self) -> None:
        self._anchor_pos_s = self.position_s
        self._anchor_clock = self._clock()

    def play(self) -> None:
        """Start or resume playing from the current position."""
        if not self._playing:
            self._anchor_clock = self._clock()
            self._playing = True

    def pause(self) -> None:
        """Hold the current position."""
        if self._playing:
            self._reanchor()
            self._playing = False

    def seek(self, t_s: float) -> None:
        """Jump to `t_s` s from the start; the next `due()` starts with the message there."""
        target = min(max(float(t_s), 0.0), self._duration_s)
        self._anchor_pos_s = target
        self._anchor_clock = self._clock()
        self._index = bisect.bisect_left(self._times_ns, self._start_ns + round(target * 1e9))

    def due(self) -> list[ReplayMessage]:
        """Messages whose recorded time is at or before the current position, in order."""
        limit_ns = self._start_ns + round(self.position_s * 1e9)
        end = bisect.bisect_right(self._times_ns, limit_ns, lo=self._index)
        batch = self._items[self._index : end]
        self._index = end
        return [self._decode(item) for item in batch]

    def drain(self) -> Iterator[ReplayMessage]:
        """Every remaining message at once, ignoring the clock (`--max`)."""
        while self._index < len(self._items):
            item = self._items[self._index]
            self._index += 1
            self._anchor_pos_s = (item[0] - self._start_ns) / 1e9
            yield self._decode(item)

    def wait_s(self) -> float:
        """Clock seconds until the next message is due (inf when paused or finished)."""
        if self.finished or not self._playing:
            return math.inf
        next_s = (self._times_ns[self._index] - self._start_ns) / 1e9
        return max(0.0, (next_s - self.position_s) / self._speed)

    def _decode(self, item: tuple[int, str, bytes]) -> ReplayMessage:
        log_ns, topic, data = item
        try:
            message = json.loads(data)
        except (UnicodeDecodeError, json.JSONDecodeError):
            message = {}
        return ReplayMessage(topic, (log_ns - self._start_ns) / 1e9, log_ns, message)


def _json_topics(recording: Recording) -> set[str]:
    return {t for t, info in recording.topic_info.items() if info.message_encoding == "json"}


def _check_speed(value: float) -> float:
    speed = float(value)
    if not (speed > 0 and math.isfinite(speed)):
        raise RecordingError(f"replay speed must be a positive number, got {value!r}")
    return speed


@dataclass(frozen=True, slots=True)
class ReplayReport:
    """What a headless replay played."""

    messages: int
    duration_s: float
    lines: int


def run_headless(
    player: Player,
    out: TextIO,
    *,
    as_fast_as_possible: bool = False,
    sleep: Callable[[float], None] = time.sleep,
    max_wait_s: float = 0.25,
    on_message: Callable[[ReplayMessage], None] | None = None,
) -> ReplayReport:
    """Play to the end, printing one status line per recorded second (and one at the end);
    `on_message` sees every message as it is played (the live view)."""
    tracker = SignalTracker()
    next_line_s = 1.0
    lines = 0
    played = 0

    def consume(batch: Iterable[ReplayMessage]) -> None:
        nonlocal next_line_s, lines, played
        for msg in batch:
            while msg.t_s >= next_line_s:
                print(tracker.status_line(next_line_s), file=out)
                lines += 1
                next_line_s += 1.0
            tracker.update(msg.topic, msg.message)
            if on_message is not None:
                on_message(msg)
            played += 1

    if as_fast_as_possible:
        consume(player.drain())
    else:
        player.play()
        while not player.finished:
            consume(player.due())
            wait = player.wait_s()
            if wait > 0 and not player.finished:
                sleep(min(wait, max_wait_s))
    print(tracker.status_line(player.duration_s), file=out)
    lines += 1
    return ReplayReport(messages=played, duration_s=player.duration_s, lines=lines)
