"""What happens to a mission's vehicles, as named events: said to the pilot and recorded.

A mission's progress lines were free text; the events are an enum so that a recording can be
searched for them (`/mission/event`: the event's value, the vehicle, a detail line) and a test
can assert on what happened rather than on wording.
"""

from __future__ import annotations

import enum
from collections.abc import Callable

from gcs.mission.recording import TopicSink

EVENT = "/mission/event"


class MissionEvent(enum.Enum):
    """One step of a vehicle's (or the team's) mission."""

    SESSION_READY = "session_ready"  # every vehicle's station is up and checked
    ARMING = "arming"
    ARM_REFUSED = "arm_refused"  # a vehicle's firmware refused to arm (why): asked again
    ARMED = "armed"  # every vehicle armed, on the floor, throttle minimum
    DISARMED_ON_FLOOR = "disarmed_on_floor"  # the team took too long: disarmed before take-off
    TAKING_OFF = "taking_off"
    AIRBORNE = "airborne"  # every vehicle at its hover point: the planner starts
    SAMPLE_DROPPED = "sample_dropped"  # a count not taken as a sample: off mission or off height
    OFF_MISSION = "off_mission"  # the link or the autopilot took a vehicle: the mission stops
    LEFT_TO_ITSELF = "left_to_itself"  # not landed by the station: its LAND or failsafe does
    LANDING = "landing"
    LANDED = "landed"  # on the floor and disarmed


class EventLog:
    """Tells the pilot (a progress callback) and the recording (any `put(topic, t, payload)`)."""

    def __init__(self, recording: TopicSink | None, progress: Callable[[str], None] | None) -> None:
        """Events go to `recording` (None: nowhere) and as lines to `progress`."""
        self._rec = recording
        self._progress = progress
        self.seen: list[tuple[float, MissionEvent, int | None, str]] = []

    def __call__(self, t_s: float, event: MissionEvent, vehicle: int | None = None,
                 detail: str = "") -> None:
        """Record one event at station time `t_s`."""
        self.seen.append((t_s, event, vehicle, detail))
        if self._rec is not None:
            self._rec.put(EVENT, t_s, {"event": event.value, "vehicle": vehicle or 0,
                                       "detail": detail})
        if self._progress is not None:
            who = f"vehicle {vehicle}: " if vehicle is not None else ""
            words = event.value.replace("_", " ")
            self._progress(f"{who}{words}" + (f" ({detail})" if detail else ""))

    def say(self, line: str) -> None:
        """A progress line that is no event (a planner step, a sample)."""
        if self._progress is not None:
            self._progress(line)
