"""`StationSession` in lockstep: the bundled SITL in this process, on the station's clock.

Everything after the SITL's start is the session a pilot gets: a recorder per vehicle, the link
opened and brought up, the throttle curve read, the pre-flight checks, motion capture and a
`Station`. Only what differs is here: the SITL is the one `gcs.lockstep.open_simulator` gives
(the bundled SITL in this process, `lab.lockstep`) instead of a subprocess, the clock is its
`LockstepClock`, the truth reports are taken on the station's tick, and the stations are run by
`run_tick()` (see `tick`) instead of loop threads.

A campaign may hand over an already loaded world (its noise and floor varied) and a station
configuration object instead of files; a pilot's `fly --lockstep` passes files as over TCP.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from firmware_link.truth_link import TruthLink
from gcs.config import StationConfig, load_config
from gcs.core.landing import may_leave, must_land
from gcs.errors import UsageError
from gcs.lockstep import LockstepOptions, SteppedTruth, TeamClock, open_simulator
from gcs.station.session import SCORED_COMMANDS, SessionOptions, StationSession

LOCKSTEP_EPOCH_NS = 946_684_800 * 10**9
"""2000-01-01T00:00:00Z: where simulated time zero sits on a lockstep recording's timeline. A
simulated flight has no date of its own, and a wall-clock anchor would make two recordings of one
seed differ (the metadata's `started_utc` says when it was flown)."""


CONNECT_AFTER_S = (0.2, 1.2)
"""When the station connects, in simulated seconds after the SITL started (seeded)."""
CONNECT_STREAM = 0x10C5  # the seed's stream for that choice, apart from the SITL's own
POLL_S = 0.1


class LockstepSession(StationSession):
    """Context manager: the vehicles' stations on the bundled SITL's simulated clock."""

    recording_anchor_ns = LOCKSTEP_EPOCH_NS
    recording_blocks = True  # no wall clock to keep up with: nothing recorded may be dropped

    def __init__(self, options: SessionOptions, *, world: Any = None,
                 config: StationConfig | None = None, noise: bool = True,
                 faults: dict[str, Any] | None = None) -> None:
        self._refuse(options)
        self._world = world if world is not None else options.world
        self._config = config
        self._noise = noise
        truth = options.command in SCORED_COMMANDS or options.metadata.get("truth") == "on"
        self.sitl = open_simulator(LockstepOptions(
            profile=options.profile, world=self._world, vehicles=max(options.sysids),
            seed=options.seed or 0, noise=noise, truth=truth, signing_key=None, faults=faults))
        super().__init__(options)
        self._stack.callback(self.sitl.close)
        self.clock = self.sitl.clock

    @staticmethod
    def _refuse(o: SessionOptions) -> None:
        """Lockstep flies the bundled SITL only, over its (unthrottled) in-memory link."""
        for flag, given in (("--connect", o.connect is not None), ("--mocap", o.mocap is not None),
                            ("--serial", o.serial), ("--speedup", o.speedup != 1.0),
                            ("--foxglove", o.foxglove is not None),
                            ("--signing-key", o.signing_key is not None),
                            ("--forward", bool(getattr(o, "forward", ())))):
            if given:
                raise UsageError(f"--lockstep: {flag} cannot be used with it (lockstep flies "
                                 "the bundled SITL in this process on simulated time)")

    def _open(self) -> None:
        config = self._config if self._config is not None else load_config(self.options.config)
        # a lockstep loop never waits: at real-time priority it would only take a core from
        # every other process on the machine (and a Ray worker would keep it for later tasks)
        config = dataclasses.replace(config, realtime_priority=0)
        # Over TCP the station comes to a SITL that has run for a while, so its ticks, the
        # SITL's and the SITL's sonar pings meet at a phase the moment decides; a lockstep
        # station connecting at a fixed simulated time would meet them at one phase for every
        # seed (which readings look repeated, say), a bias no seed averages out. The seed
        # chooses the moment instead.
        rng = np.random.default_rng([self.options.seed or 0, CONNECT_STREAM])
        self.sitl.sitl.advance_to(float(rng.uniform(*CONNECT_AFTER_S)))
        for sysid in self.options.sysids:
            self.vehicles[sysid] = self._open_vehicle(sysid, self.sitl.url(sysid),
                                                      self.sitl.mocaps.get(sysid), None, config)
        watch = getattr(self.sitl, "watch_station", None)
        if watch is not None:  # a fault search's pilot and phases (lab.faultsearch)
            for sysid, v in self.vehicles.items():
                watch(sysid, v.station)
        # registered after every station's stop, so it runs first: a team lands together
        self._stack.callback(self._land_together)
        if self.sitl.truth is not None:
            for sysid, v in self.vehicles.items():
                truth = SteppedTruth(TruthLink.open(self.sitl.truth, clock=self.clock.now_s),
                                     sysid)
                self._stack.callback(truth.close)
                v.station.add_listener(truth.pump)
                v.truth = truth  # type: ignore[assignment]

    def team_clock(self) -> TeamClock:
        """The clock a mission waits on: each wait flies every vehicle's station."""
        return TeamClock(self.sitl.sitl, [v.station for v in self.vehicles.values()])

    def _land_together(self) -> None:
        """Leaving with vehicles that may fly: ask all to land, and fly all while they do.

        Each station's own stop lands its vehicle on its own ticks; one after the other, the
        vehicles waiting their turn would get no overrides for seconds."""
        flying = [v.station for v in self.vehicles.values()
                  if v.station.error is None
                  and must_land(v.station.snapshot(loop_stats=False).state)]
        if len(flying) < 2:
            return
        clock = TeamClock(self.sitl.sitl, list(flying))
        deadline = clock.now_s() + max(st.supervisor_params.quit_timeout_s for st in flying)
        next_ask = clock.now_s()
        while clock.now_s() < deadline:
            if clock.now_s() >= next_ask:  # asked again each second, as a stop does
                for st in flying:
                    st.quit()
                next_ask += 1.0
            clock.sleep_until(clock.now_s() + POLL_S)
            if all(st.error is not None
                   or may_leave(st.snapshot(loop_stats=False).state) for st in flying):
                return

    def tick(self) -> None:
        """One tick of every vehicle's station (the simulation runs up to each deadline)."""
        for v in self.vehicles.values():
            v.station.run_tick()
