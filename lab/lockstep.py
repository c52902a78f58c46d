"""The bundled SITL in this process for lockstep flights (`gcs.lockstep` is the station's side).

`install()` hands `BundledLockstep` to the station (`gcs.lockstep.use_simulator`): every
program that flies lockstep (the `quadgcs` console script, a campaign's worker, a bench program)
calls it once before its first flight.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from firmware_link import memory
from gcs.errors import UsageError
from gcs.lockstep import LockstepClock, LockstepOptions, use_simulator
from gcs.station.station import Station
from sitl import lockstep as sitl_lockstep

_instances = itertools.count(1)


class FaultSchedule(Protocol):
    """A flight's fault schedule, put on the SITL and watching its stations
    (`lab.faultsearch.inject.FaultPlan`)."""

    def attach(self, sitl: sitl_lockstep.LockstepSitl) -> sitl_lockstep.PortFaults: ...

    def watch_station(self, sysid: int, station: Station) -> None: ...


ScheduleOpener = Callable[[Any, int, Any], FaultSchedule]
"""(what a flight's options carry as its schedule, the seed, its FlightPlan) -> the schedule"""
_schedule_openers: list[ScheduleOpener] = []


def use_schedules(opener: ScheduleOpener) -> None:
    """Let lockstep flights fly fault schedules (`lab.faultsearch` calls this)."""
    if opener not in _schedule_openers:
        _schedule_openers.append(opener)


def install() -> None:
    """Let the station's lockstep flights fly the bundled SITL (idempotent)."""
    use_simulator(BundledLockstep)


def _faulty_sysids(given: Any, vehicles: int) -> set[int]:
    """The sysids a fault hits: every vehicle, or those listed (each one of them)."""
    every = set(range(1, vehicles + 1))
    if given is None:
        return every
    listed = [given] if isinstance(given, int) else given
    if (not isinstance(listed, list | tuple) or not listed
            or not all(isinstance(v, int) and not isinstance(v, bool) for v in listed)
            or not set(listed) <= every):
        raise ValueError(f"faults' vehicles {given!r}: expected sysids among 1..{vehicles}")
    return set(listed)


class BundledLockstep:
    """The bundled SITL in this process: its ports plugged in as `mem:` connection strings."""

    def __init__(self, options: LockstepOptions) -> None:
        try:
            self.sitl = sitl_lockstep.start(options.profile, options.world, options.vehicles,
                                            options.seed, options.noise, options.signing_key)
            given = dict(options.faults or {})
            hit = _faulty_sysids(given.pop("vehicles", None), options.vehicles)
            stall = given.pop("stall", None)
            if stall is not None:
                self.sitl.stall = sitl_lockstep.Stall(*stall)
            schedule = given.pop("schedule", None)
            flight = given.pop("schedule_flight", None)  # the FlightPlan it must fit in
            faults: sitl_lockstep.PortFaults | None = (
                sitl_lockstep.LinkFaults(**{"seed": options.seed, **given}) if given else None)
            self.plan: FaultSchedule | None = None
            if schedule is not None:  # a fault search's schedule (or `fly --faults FILE`)
                if given:
                    raise ValueError("a fault schedule carries its own link faults; expected "
                                     "no other link faults beside it")
                if not _schedule_openers:
                    raise ValueError("fault schedules: this program cannot fly them (run it "
                                     "as quadgcs)")
                self.plan = _schedule_openers[-1](schedule, options.seed, flight)
                faults = self.plan.attach(self.sitl)
        except (ValueError, OSError, TypeError) as exc:
            where = f"--world {options.world}: " if isinstance(options.world, Path) else ""
            raise UsageError(f"{where}{exc}") from None
        self.clock = LockstepClock(self.sitl)
        self._prefix = f"lockstep{next(_instances)}"
        self._names: list[str] = []
        self.ports = {s: self.sitl.vehicle_port(s, faults if s in hit else None)
                      for s in range(1, options.vehicles + 1)}
        self.vehicles = {s: self._plug(f"vehicle{s}", p) for s, p in self.ports.items()}
        # one motion-capture client per vehicle, as over TCP: readers of one pipe would share
        # out its bytes between them
        self.mocaps = ({s: self._plug(f"mocap{s}", self.sitl.mocap_port()) for s in self.ports}
                       if self.sitl.mocap_enabled else {})
        self.mocap = self.mocaps.get(1)
        self.truth = self._plug("truth", self.sitl.truth_port()) if options.truth else None

    def _plug(self, what: str, port: sitl_lockstep.MemoryPort) -> str:
        name = f"{self._prefix}/{what}"
        self._names.append(name)
        return memory.plug(name, port)

    def watch_station(self, sysid: int, station: Station) -> None:
        """The session built `station` for vehicle `sysid`: a fault schedule's pilot acts
        through it and times its phases on it."""
        if self.plan is not None:
            self.plan.watch_station(sysid, station)

    def url(self, sysid: int = 1) -> str:
        """The vehicle's connection string."""
        return self.vehicles[sysid]

    def close(self) -> None:
        """Unplug every port (the simulation itself is garbage once nobody holds it)."""
        for name in self._names:
            memory.unplug(name)
        self._names.clear()
