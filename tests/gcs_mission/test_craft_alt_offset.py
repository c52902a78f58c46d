"""The mission's altitude re-aim: motion capture against an estimate that is live, or stale."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from gcs.clock import SimClock
from gcs.errors import RuntimeFault
from gcs.mission.craft import Craft
from gcs.supervisor import LinkHealth


class FakeStation:
    """What Craft asks of a station: its snapshot, and the holds it is given."""

    def __init__(self) -> None:
        self.clock = SimClock()
        self.error = None
        self.health = LinkHealth.OK
        self.estimate_m = 1.0
        self.mocap_m = 1.0
        self.alt_holds: list[float] = []

    def add_record_listener(self, _: Any) -> None:
        pass

    def snapshot(self, loop_stats: bool = False) -> Any:
        return SimpleNamespace(link_health=self.health,
                               estimate=SimpleNamespace(alt_m=self.estimate_m),
                               mocap=SimpleNamespace(pos_n=(0.0, 0.0, -self.mocap_m)))

    def set_position_setpoint(self, _: Any) -> None:
        pass

    def alt_hold(self, on: bool, setpoint_m: float, rate_mps: float | None = None) -> None:
        self.alt_holds.append(setpoint_m)


def craft() -> tuple[Craft, FakeStation]:
    station = FakeStation()
    c = Craft(3, station)  # type: ignore[arg-type]
    c.command((0.0, 0.0, -1.0))
    return c, station


def test_a_live_estimate_far_from_motion_capture_stops_the_mission() -> None:
    c, station = craft()
    station.mocap_m = 2.6  # climbed 1.6 m the estimate never saw
    with pytest.raises(RuntimeFault, match=r"vehicle 3: altitude estimate 1\.00 m disagrees"):
        c.refresh()


@pytest.mark.parametrize("health", [LinkHealth.DEGRADED, LinkHealth.LOST])
def test_a_stale_estimate_is_neither_judged_nor_re_aimed(health: LinkHealth) -> None:
    # a radio fade: the estimate stopped with the telemetry while motion capture watches the
    # vehicle's own failsafe seconds; that gap is the link's, which the mission sees as such
    c, station = craft()
    sent = list(station.alt_holds)
    station.health, station.mocap_m = health, 2.6
    c.refresh()
    assert station.alt_holds == sent
