"""The one landing of `fly` and teams (`gcs.landing`): a scripted vehicle on a simulated clock,
the caller's look-and-wait as a port, no sockets."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from firmware_link.records import FlightMode, MocapPose
from gcs.clock import SimClock
from gcs.estimation import AltEstimate, SonarStatus
from gcs.landing import HANDOVER_ALT_M, STILL_S, LandingView, descend, hand_over, may_descend
from gcs.supervisor import SupervisorState

POLL_S = 0.1


@dataclass(frozen=True)
class View:
    state: SupervisorState
    armed: bool
    estimate: AltEstimate | None
    mocap: MocapPose | None


def _estimate(t_s: float, alt_m: float) -> AltEstimate:
    return AltEstimate(t_s, alt_m, 0.0, 0.0, 0.0, True, SonarStatus.USED, 0.0, 0.0, False,
                       0.01, 0)


@dataclass
class Vehicle:
    """Sinks at the commanded rate from `alt_m` until `floor_m` (a box top: the estimate still
    reads from the room's floor, `est_offset_m` higher); LAND disarms it after `land_s`."""

    clock: SimClock
    alt_m: float
    floor_m: float = 0.0
    est_offset_m: float = 0.0
    land_s: float | None = 2.0
    rate_mps: float = 0.0
    land_at_s: float | None = None
    asked: list[str] = field(default_factory=list)

    def set_sticks(self, roll_us: int, pitch_us: int, yaw_us: int, throttle_us: int) -> None:
        self.asked.append(f"sticks {throttle_us}")

    def set_mode(self, mode: FlightMode) -> None:
        self.asked.append(f"mode {FlightMode(mode).name}")
        self.land_at_s = self.clock.now_s()

    def request_disarm(self) -> None:
        self.asked.append("disarm")

    def alt_hold(self, on: bool, setpoint_m: float | None = None,
                 rate_mps: float | None = None) -> None:
        self.asked.append(f"hold {setpoint_m} at {rate_mps}")
        self.rate_mps = rate_mps or 0.0

    def view(self) -> View:
        t = self.clock.now_s()
        alt = max(self.floor_m, self.alt_m)
        armed = not (self.land_s is not None and self.land_at_s is not None
                     and t - self.land_at_s >= self.land_s)
        pose = MocapPose(t, 1, (0.0, 0.0, -alt), (1.0, 0.0, 0.0, 0.0), int(t * 1e6))
        return View(SupervisorState.HOLD, armed, _estimate(t, alt + self.est_offset_m), pose)


class Port:
    def __init__(self, vehicle: Vehicle) -> None:
        self.v = vehicle
        self.looks = 0

    def now_s(self) -> float:
        return self.v.clock.now_s()

    def look(self, vehicle: int) -> View:
        self.looks += 1
        return self.v.view()

    def idle(self) -> None:
        v = self.v
        v.alt_m -= v.rate_mps * POLL_S
        v.clock.sleep_until(v.clock.now_s() + POLL_S)


def waiter(v: Vehicle) -> Callable[[Callable[[LandingView], bool], float], bool]:
    def wait(pred: Callable[[LandingView], bool], timeout_s: float) -> bool:
        deadline = v.clock.now_s() + timeout_s
        while v.clock.now_s() < deadline:
            if pred(v.view()):
                return True
            v.clock.sleep_until(min(v.clock.now_s() + POLL_S, deadline))
        return False
    return wait


def test_the_descent_ends_at_the_hand_over_height() -> None:
    v = Vehicle(SimClock(10.0), alt_m=1.0)
    assert descend(v, Port(v), 1, 0.3, 20.0)
    assert v.asked == ["hold 0.0 at 0.3"]
    assert HANDOVER_ALT_M - 0.3 * POLL_S <= v.alt_m < HANDOVER_ALT_M
    assert v.clock.now_s() - 10.0 < (1.0 - HANDOVER_ALT_M) / 0.3 + 2 * POLL_S


def test_standing_on_a_box_ends_the_descent_after_a_still_second() -> None:
    # the estimate still measures from the room's floor: it never reaches the hand-over height
    v = Vehicle(SimClock(10.0), alt_m=1.0, floor_m=0.5, est_offset_m=0.5)
    assert descend(v, Port(v), 1, 0.3, 20.0)
    on_box_s = 10.0 + (1.0 - 0.5) / 0.3
    assert on_box_s + STILL_S <= v.clock.now_s() <= on_box_s + STILL_S + 3 * POLL_S


def test_a_descent_that_does_not_end_in_time_says_so() -> None:
    v = Vehicle(SimClock(10.0), alt_m=3.0)
    assert not descend(v, Port(v), 1, 0.3, 2.0)
    assert v.clock.now_s() - 10.0 <= 2.0 + POLL_S + 1e-9


def test_land_touches_down_and_disarms_without_a_request() -> None:
    v = Vehicle(SimClock(10.0), alt_m=0.1, land_s=2.0)
    assert hand_over(v, waiter(v), (15.0, 3.0, 3.0, 3.0))
    assert v.asked == ["sticks 1000", "mode LAND"]  # throttle minimum before LAND


def test_a_vehicle_that_stays_armed_gets_a_disarm_after_every_wait_and_a_no() -> None:
    v = Vehicle(SimClock(10.0), alt_m=0.1, land_s=None)
    assert not hand_over(v, waiter(v), (10.0, 10.0, 10.0, 10.0))
    assert v.asked == ["sticks 1000", "mode LAND", "disarm", "disarm", "disarm", "disarm"]
    assert abs(v.clock.now_s() - 50.0) < 1e-6


def test_only_a_pc_hold_may_descend() -> None:
    v = Vehicle(SimClock(10.0), alt_m=0.06)
    on_floor = View(SupervisorState.MANUAL, True, _estimate(10.0, 0.06), None)
    assert may_descend(v.view()) and not may_descend(on_floor)
