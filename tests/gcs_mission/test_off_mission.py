"""When the autopilot takes a mission's vehicle over, the mission notices and says why."""

from types import SimpleNamespace
from typing import Any

from firmware_link.records import Battery, FlightMode, StatusText
from gcs.mission.off_mission import off_mission


def _snap(mode: int = FlightMode.STABILIZE, armed: bool = True, link_lost: bool = False,
          latest: dict | None = None) -> Any:
    # only what `off_mission` reads of a StationSnapshot
    return SimpleNamespace(vehicle_mode=int(mode), armed=armed, link_lost=link_lost,
                           latest=latest or {})


def test_a_vehicle_flying_in_stabilize_is_on_its_mission() -> None:
    assert off_mission(_snap(), 12.0) is None
    assert off_mission(_snap(mode=-1), 12.0) is None


def test_a_battery_failsafe_land_names_the_mode_the_battery_and_the_vehicle_text() -> None:
    latest = {Battery: Battery(t_s=1.0, sysid=1, voltage_v=10.21, current_a=20.0,
                               remaining_pct=25),
              StatusText: StatusText(t_s=1.0, sysid=1, severity=2,
                                     text="Battery failsafe: 10.21V")}
    why = off_mission(_snap(mode=FlightMode.LAND, latest=latest), 387.4)
    assert why == ("vehicle switched to LAND (after 387 s of flight, battery 10.21 V 25 %, "
                   "vehicle said 'Battery failsafe: 10.21V')")


def test_disarmed_link_lost_and_unknown_modes_are_off_the_mission() -> None:
    assert str(off_mission(_snap(armed=False), 5.0)).startswith("vehicle disarmed")
    assert str(off_mission(_snap(link_lost=True), 5.0)).startswith("vehicle link lost")
    assert "switched to mode 99" in str(off_mission(_snap(mode=99), 5.0))
