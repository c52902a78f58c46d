"""The end of every scripted flight, `fly`'s vehicle and each of a team's: descend under PC
control to a few centimetres, then LAND mode touches down and disarms (a disarm request follows
each wait it does not). PC hold stays on until a heartbeat shows LAND, so the vehicle is never
left without a throttle.

Over a box the sonar-based estimate may still be measured from the floor, so it never falls
below the hand-over height: motion capture seeing no descent for a second ends the PC descent
too. How to look and wait stays the caller's (`gcs.launch.LaunchPort`), as for the launch.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from firmware_link.records import FlightMode, MocapPose
from gcs.estimation import AltEstimate
from gcs.launch import STICK_MID_US, STICK_MIN_US
from gcs.supervisor import SupervisorState

HANDOVER_ALT_M = 0.15  # below this (estimate), LAND mode finishes the touch-down
STILL_MPS = 0.05  # sinking slower than this (mocap) for STILL_S: standing on something
STILL_S = 1.0


class LandingView(Protocol):
    """What a landing reads of one vehicle's station snapshot."""

    @property
    def state(self) -> SupervisorState: ...
    @property
    def armed(self) -> bool: ...
    @property
    def estimate(self) -> AltEstimate | None: ...
    @property
    def mocap(self) -> MocapPose | None: ...


class LandingPort(Protocol):
    """The caller's ways of looking at a vehicle and of letting time pass."""

    def now_s(self) -> float: ...
    def look(self, vehicle: int) -> LandingView: ...
    def idle(self) -> None: ...


class LandingStation(Protocol):
    """What a landing asks of one vehicle's station."""

    def set_sticks(self, roll_us: int, pitch_us: int, yaw_us: int, throttle_us: int) -> None: ...
    def set_mode(self, mode: FlightMode) -> None: ...
    def request_disarm(self) -> None: ...
    def alt_hold(self, on: bool, setpoint_m: float | None = None,
                 rate_mps: float | None = None) -> None: ...


Waiter = Callable[[Callable[[LandingView], bool], float], bool]
"""Wait up to a timeout (s) for a condition on the vehicle's snapshot; whether it held."""


def may_descend(view: LandingView) -> bool:
    """Whether the PC may fly the descent: only from its hold. Asked of a vehicle on the floor,
    a hold request would be a take-off; one the PC does not fly goes straight to LAND."""
    return view.state is SupervisorState.HOLD


def descend(station: LandingStation, port: LandingPort, vehicle: int, rate_mps: float,
            timeout_s: float, handover_m: float = HANDOVER_ALT_M) -> bool:
    """From a PC hold (`may_descend`), descend under PC control at `rate_mps` until near the
    surface below or no longer sinking; False when `timeout_s` passed first."""
    station.alt_hold(True, 0.0, rate_mps=rate_mps)
    deadline = port.now_s() + timeout_s
    still_since: float | None = None
    last: tuple[float, float] | None = None  # (station time, mocap z)
    while True:
        view = port.look(vehicle)
        now = port.now_s()
        if view.estimate is not None and view.estimate.alt_m < handover_m:
            return True
        z = view.mocap.pos_n[2] if view.mocap is not None else None
        if z is not None and last is not None and now > last[0]:
            if (z - last[1]) / (now - last[0]) < STILL_MPS:
                still_since = now if still_since is None else still_since
                if now - still_since >= STILL_S:
                    return True
            else:
                still_since = None
        if z is not None:
            last = (now, z)
        if now >= deadline:
            return False
        port.idle()


def hand_over(station: LandingStation, wait: Waiter, waits_s: Sequence[float]) -> bool:
    """Throttle at minimum and LAND, which touches down and disarms by itself; after each of
    `waits_s` that ends with the vehicle still armed, a disarm request. Whether it disarmed."""
    station.set_sticks(STICK_MID_US, STICK_MID_US, STICK_MID_US, STICK_MIN_US)
    station.set_mode(FlightMode.LAND)  # PC hold stays on until a heartbeat shows LAND
    for wait_s in waits_s:
        if wait(lambda s: not s.armed, wait_s):
            return True
        station.request_disarm()
    return False
