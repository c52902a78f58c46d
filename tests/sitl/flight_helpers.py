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


PAST_PREARM_S = 3.2  # both profiles refuse to arm for 3 s after boot (copter4's short default)


def make(profile: Profile, seed: int = 1, **kw: Any) -> tuple[Simulation, MemoryGcs]:
    """A one-vehicle simulation past its pre-arm boot delay, with a GCS streaming ALL at 10 Hz
    (8.3 Hz on apm25, which delivers 50 / (int(50 / rate) + 1) Hz)."""
    sim = Simulation(big_room(), profile, 1, seed=seed, **kw)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    gcs.heartbeat()
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, STREAM_ALL, 10, 1))
    gcs.run(PAST_PREARM_S)
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
    """Latest ground-truth altitude (SIM_STATE), metres above the floor (from `msgs` when they
    hold one, else from everything received: apm25 streams at 8.3 Hz, not every 0.1 s)."""
    found = gcs.of_type("SIM_STATE", msgs)
    last = found[-1] if found else gcs.of_type("SIM_STATE")[-1]
    return last.alt - gcs.sim.world.origin.alt_amsl_m


def wait_ack(gcs: MemoryGcs, pilot: Pilot, command: int, timeout_s: float = 3.0) -> Any:
    """Fly until the COMMAND_ACK of `command` arrives (3.2.1 answers an arm after 1.9 s)."""
    end = gcs.sim.t_s + timeout_s
    while gcs.sim.t_s < end:
        acks = [a for a in gcs.of_type("COMMAND_ACK", pilot.fly(0.05)) if a.command == command]
        if acks:
            return acks[-1]
    raise AssertionError(f"no COMMAND_ACK for {command} within {timeout_s} s")


def arm(gcs: MemoryGcs, pilot: Pilot) -> Any:
    """Arm with the throttle down; returns the COMMAND_ACK. On copter4 it also waits out the
    2 s arming delay and the spool to ground idle, so the motors are ready for the throttle."""
    pilot.sticks[2] = 1000
    pilot.fly(0.1)
    gcs.command(1, ARM, 1.0)
    ack = wait_ack(gcs, pilot, ARM)
    if ack.result == 0 and gcs.sim.profile is Profile.COPTER4:
        pilot.fly(2.6)
    return ack


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
        pilot.fly(0.1)
        if gcs.of_type("SIM_STATE")[-1].vd > -0.2:
            break
    pilot.sticks[2] = HOVER_STICK_US
