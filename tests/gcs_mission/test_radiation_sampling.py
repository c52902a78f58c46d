"""Radiation samples counted on the move: where a reading is attributed, and where the vehicle
is sent, against a scripted vehicle on a simulated clock (no SITL)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import pytest

from firmware_link.records import Radiation
from gcs.clock import SimClock
from gcs.mission import vehicle_radiation as vr
from gcs.mission.loop_radiation import count_time_s
from planners.geometry import Vec3
from planners.radiation import RadiationMapperParams

PARAMS = RadiationMapperParams(x_min_m=-9.5, x_max_m=9.5, y_min_m=-9.5, y_max_m=9.5,
                               dwell_s=1.0, target_counts=800.0)
WINDOW_S = PARAMS.detector_window_s


@dataclass
class MovingCraft:
    """Flies towards its set point at `speed_mps` without braking; motion capture at 100 Hz and
    a detector reporting `cps` every window."""

    clock: SimClock
    start: tuple[float, float]
    speed_mps: float = 1.0
    cps: float = 1000.0
    set_n: tuple[float, float] | None = None
    t_set: float = 0.0
    from_n: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        self.from_n = self.start

    def _at(self, t: float) -> tuple[float, float]:
        if self.set_n is None:
            # no set point yet: moving along +x (a leg in progress)
            return (self.from_n[0] + self.speed_mps * t, self.from_n[1])
        dx, dy = self.set_n[0] - self.from_n[0], self.set_n[1] - self.from_n[1]
        d = math.hypot(dx, dy)
        s = min(d, self.speed_mps * (t - self.t_set))
        return (self.from_n[0] + s * dx / d, self.from_n[1] + s * dy / d) if d else self.from_n

    def command(self, target: Vec3) -> None:
        now = self.clock.now_s()
        self.from_n, self.set_n, self.t_set = self._at(now), (target[0], target[1]), now

    def refresh(self) -> None:
        pass

    def position_n(self) -> Vec3:
        x, y = self._at(self.clock.now_s())
        return (x, y, -1.0)

    def mocap_since(self, t_s: float) -> list[tuple[float, Vec3]]:
        ticks = range(math.ceil(t_s * 100 - 1e-9), math.floor(self.clock.now_s() * 100 + 1e-9) + 1)
        return [(k / 100, (*self._at(k / 100), -1.0)) for k in ticks if k >= 0]

    def radiation_since(self, t_s: float) -> list[Radiation]:
        ticks = range(math.ceil(t_s / WINDOW_S - 1e-9),
                      math.floor(self.clock.now_s() / WINDOW_S + 1e-9) + 1)
        return [Radiation(k * WINDOW_S, 1, self.cps) for k in ticks if k > 0]


def team(clock: SimClock) -> Any:
    return SimpleNamespace(clock=clock, spec=SimpleNamespace(position_tolerance_m=0.15))


def test_a_reading_on_the_move_is_attributed_to_the_mean_position_over_its_windows() -> None:
    clock = SimClock(1.05)
    craft = MovingCraft(clock, start=(0.0, 0.0))  # passing x = 1.05 m at 1 m/s
    c = vr.count_on_the_move(team(clock), craft, PARAMS)  # type: ignore[arg-type]
    cps, counted_s, at = c.counts_per_s, c.counted_s, c.at_n
    # 200 counts a window: four windows, (1.0, 1.2] to (1.6, 1.8], their centres 1.1 to 1.7 m
    assert cps == 1000.0 and counted_s == pytest.approx(0.8)
    assert at[0] == pytest.approx(1.4, abs=0.01) and at[1:] == (0.0, -1.0)


def test_the_vehicle_is_sent_past_the_sample_point_and_counts_before_it() -> None:
    clock = SimClock(0.0)
    craft = MovingCraft(clock, start=(0.0, 0.0))
    craft.command((0.0, 0.0, -1.0))
    count_s = count_time_s(1000.0, PARAMS)
    assert count_s == pytest.approx(0.8)
    assert vr.fly_to_sample(team(clock), craft, (2.0, 0.0, -1.0), PARAMS,  # type: ignore[arg-type]
                             count_s, timeout_s=10.0)
    assert craft.set_n == pytest.approx((2.0 + vr.SAMPLE_THROUGH_M, 0.0))
    # half the count's travel (0.4 m at 1 m/s) before the point: the count is centred on it
    assert craft.position_n()[0] == pytest.approx(1.6, abs=0.06)


def test_at_the_floors_edge_the_vehicle_is_held_at_the_sample_point() -> None:
    clock = SimClock(0.0)
    craft = MovingCraft(clock, start=(8.0, 0.0))
    craft.command((8.0, 0.0, -1.0))
    assert vr.fly_to_sample(team(clock), craft, (9.3, 0.0, -1.0), PARAMS,  # type: ignore[arg-type]
                             count_time_s(50.0, PARAMS), timeout_s=10.0)
    assert craft.set_n == pytest.approx((PARAMS.x_max_m, 0.0))


def test_counting_time_follows_the_last_rate() -> None:
    assert count_time_s(2500.0, PARAMS) == pytest.approx(0.4)  # 800 counts in two windows
    assert count_time_s(50.0, PARAMS) == PARAMS.dwell_s  # background: the whole dwell
    assert count_time_s(math.nan, PARAMS) == PARAMS.dwell_s
