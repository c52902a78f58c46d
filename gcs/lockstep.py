"""Lockstep flights: the station and a simulator in one process, on one simulated clock.

Over TCP the SITL is a separate program that keeps its own time; in lockstep it is a library
whose time the station drives: `LockstepClock.sleep_until(t)` is the simulation running up to
`t`, so the loop's wait for its next tick, the link's wait for bytes and a flight's wait for the
vehicle all cost only the CPU the simulation needs. Nothing waits on the wall clock and no
thread is involved, so a seed flies the same flight bit for bit.

The station still learns everything from MAVLink bytes: the simulator's ports are plugged in as
`mem:` connection strings (`firmware_link.memory`) and the station opens them with the same
`VehicleLink`, `MocapLink` and `TruthLink` it uses over TCP. The station never imports the
simulator: the program that has both (`lab`, the `quadgcs` console script) hands its opener to
`use_simulator`; without one, a lockstep flight is refused with one line.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from firmware_link.truth_link import TruthLink, TruthReport
from gcs.errors import UsageError


class Timeline(Protocol):
    """What the clock needs of a lockstep simulator."""

    @property
    def t_s(self) -> float: ...

    def advance_to(self, t_s: float) -> None: ...


class LockstepClock:
    """A `Clock` whose waiting runs the simulation: time passes only as fast as it computes."""

    def __init__(self, timeline: Timeline) -> None:
        self.timeline = timeline

    def now_s(self) -> float:
        """The simulated time."""
        return self.timeline.t_s

    def sleep_until(self, t_s: float) -> None:
        """Run the simulation up to `t_s`."""
        self.timeline.advance_to(t_s)


@dataclass(frozen=True, slots=True)
class LockstepOptions:
    """What to ask the bundled SITL for (as `SitlOptions` asks the program)."""

    profile: str = "apm25"
    world: Any = None  # a world TOML path, an already loaded world, or None (empty room)
    vehicles: int = 1
    seed: int = 0
    noise: bool = True
    truth: bool = False
    signing_key: bytes | None = None
    # the vehicle links' faults (sitl.lockstep.LinkFaults's fields: loss, fade, fade_start_s,
    # fade_s; seeded from `seed`; "vehicles": the sysids that suffer them, default every one;
    # "stall": [stop_s, every_s] or [stop_s, every_s, start_s], the whole SITL stopped as
    # sitl.lockstep.Stall says), None: a clean link
    faults: dict[str, Any] | None = None


class LockstepSimulator(Protocol):
    """A simulator running in this process, its ports plugged in as `mem:` connection strings
    (`lab.lockstep.BundledLockstep`)."""

    @property
    def sitl(self) -> Timeline: ...

    @property
    def clock(self) -> LockstepClock: ...

    @property
    def mocaps(self) -> Mapping[int, str]: ...

    @property
    def truth(self) -> str | None: ...

    def url(self, sysid: int = 1) -> str: ...

    def close(self) -> None: ...


SimulatorOpener = Callable[[LockstepOptions], LockstepSimulator]

_openers: list[SimulatorOpener] = []


def use_simulator(opener: SimulatorOpener) -> None:
    """Fly lockstep flights on what `opener` starts (the program that has a simulator calls
    this once, before any flight)."""
    if opener not in _openers:
        _openers.append(opener)


def open_simulator(options: LockstepOptions) -> LockstepSimulator:
    """The simulator for a lockstep flight (UsageError when this program has none)."""
    if not _openers:
        raise UsageError("--lockstep: this program has no simulator of its own; run it as "
                         "quadgcs (or python -m lab), which brings the bundled SITL")
    return _openers[-1](options)


class SteppedTruth:
    """A vehicle's truth reports, collected on the station's tick instead of by a thread (as
    `TruthRecorder` does over TCP): in lockstep a thread would read at wall-clock moments."""

    def __init__(self, link: TruthLink, sysid: int) -> None:
        self.link = link
        self.sysid = sysid
        self._reports: list[TruthReport] = []

    def pump(self, *_: object) -> None:
        """Take what arrived (a station listener: called after every tick)."""
        self._reports.extend(r for r in self.link.poll() if r.sysid == self.sysid)

    def reports(self) -> list[TruthReport]:
        """Every report so far, oldest first."""
        self.pump()
        return list(self._reports)

    def close(self) -> None:
        """Close the link. Idempotent."""
        self.link.close()


class SteppedLoop(Protocol):
    @property
    def next_deadline_s(self) -> float | None: ...


class SteppedStation(Protocol):
    """What `TeamClock` needs of a station run by `run_tick` (`gcs.station.Station`)."""

    @property
    def loop(self) -> SteppedLoop: ...

    @property
    def error(self) -> BaseException | None: ...

    def run_tick(self) -> None: ...


class TeamClock:
    """The clock a mission waits on when its vehicles' stations run in lockstep.

    Over TCP every station has a loop thread and the mission's waits are plain sleeps. Here a
    wait runs the stations' ticks due before its end, earliest first, so the shared simulation
    only ever moves forward and every vehicle is flown while the mission looks elsewhere (one
    vehicle landing while the others hold). A station whose tick raised is left out from then
    on, as its loop thread would have died: the mission sees the error on its next look.
    """

    def __init__(self, timeline: Timeline, stations: list[SteppedStation]) -> None:
        self.timeline = timeline
        self.stations = stations

    def now_s(self) -> float:
        """The simulated time."""
        return self.timeline.t_s

    def sleep_until(self, t_s: float) -> None:
        """Tick every station due before `t_s`, then run the simulation up to `t_s`."""
        live = [s for s in self.stations if s.error is None]
        while live:
            due = min(live, key=self._due_s)
            was = self._due_s(due)
            if was > t_s:
                break
            # the error is kept by the station (its snapshot raises); the mission decides
            with contextlib.suppress(Exception):
                due.run_tick()
            if due.error is not None or self._due_s(due) <= was:
                live.remove(due)  # crashed, or a stopped loop that no longer ticks
        self.timeline.advance_to(t_s)

    def _due_s(self, station: SteppedStation) -> float:
        t = station.loop.next_deadline_s
        return self.timeline.t_s if t is None else t
