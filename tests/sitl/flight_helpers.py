"""Shared set-up for SITL flight tests on the step API."""

from __future__ import annotations

import dataclasses
from typing import Any

from sitl.autopilot import Profile
from sitl.simulation import Simulation
from sitl.world import World, default_world
from tests.sitl.gcs_peer import MemoryGcs, mavlink

ARM = 400
HOVER_STICK_US = 1515  # mid throttle (control_in 500) after the 30 µs bottom dead zone
STREAM_ALL = 0


def big_room() -> World:
    """A 40 x 40 x 5 m room: a STABILIZE flight drifts a few metres and must not hit a wall."""
    return dataclasses.replace(
        default_world(), room_min_n=(-20.0, -20.0, -5.0), room_max_n=(20.0, 20.0, 0.0)
    )


def make(profile: Profile, seed: int = 1, **kw: Any) -> tuple[Simulation, MemoryGcs]:
    """A one-vehicle simulation past its gyro calibration, with a GCS streaming at 10 Hz."""
    sim = Simulation(big_room(), profile, 1, seed=seed, **kw)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    gcs.heartbeat()
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, STREAM_ALL, 10, 1))
    gcs.run(1.5)
    return sim, gcs


class Pilot:
    """Sends heartbeats at 1 Hz and overrides every tick, like a station's loop."""

    def __init__(self, gcs: MemoryGcs) -> None:
        self.gcs = gcs
        self.sticks = [1500, 1500, 1000, 1500]
        self.overrides = True
        self.heartbeats = True
        self._last_hb = -1.0

    def __call__(self) -> None:
        t = self.gcs.sim.t_s
        if self.heartbeats and t - self._last_hb >= 1.0:
            self.gcs.heartbeat()
            self._last_hb = t
        if self.overrides:
            self.gcs.override(1, *self.sticks)

    def fly(self, seconds: float) -> list[Any]:
        """Advance with this pilot on the sticks."""
        return self.gcs.run(seconds, self)


def truth_alt(gcs: MemoryGcs, msgs: list[Any] | None = None) -> float:
    """Latest ground-truth altitude (SIM_STATE), metres above the floor."""
    last = gcs.of_type("SIM_STATE", msgs)[-1]
    return last.alt - gcs.sim.world.origin.alt_amsl_m


def arm(gcs: MemoryGcs, pilot: Pilot) -> Any:
    """Arm with the throttle down; returns the COMMAND_ACK."""
    pilot.sticks[2] = 1000
    pilot.fly(0.1)
    gcs.command(1, ARM, 1.0)
    msgs = pilot.fly(0.1)
    return gcs.of_type("COMMAND_ACK", msgs)[-1]


def take_off(gcs: MemoryGcs, pilot: Pilot, alt_m: float = 1.0) -> None:
    """Arm in STABILIZE and climb on the throttle to about `alt_m`, then hover-ish."""
    ack = arm(gcs, pilot)
    assert ack.result == 0
    pilot.sticks[2] = 1650
    for _ in range(400):
        msgs = pilot.fly(0.05)
        if gcs.of_type("SIM_STATE", msgs) and truth_alt(gcs, msgs) >= alt_m * 0.6:
            break
    pilot.sticks[2] = 1450  # let the climb coast to a stop
    for _ in range(100):
        msgs = pilot.fly(0.1)
        if gcs.of_type("SIM_STATE", msgs)[-1].vd > -0.2:
            break
    pilot.sticks[2] = HOVER_STICK_US
