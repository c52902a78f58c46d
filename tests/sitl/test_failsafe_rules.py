"""The failsafe decisions of each firmware, as pure functions (sitl/autopilot/failsafe_rules.py)."""

from __future__ import annotations

import dataclasses

import pytest

from sitl.autopilot.failsafe_rules import (
    Response,
    Situation,
    gcs_apm25,
    gcs_copter4,
    radio_apm25,
    radio_copter4,
)
from sitl.autopilot.profile import FlightMode

FLYING = Situation(armed=True, mode=FlightMode.STABILIZE, landed=False, throttle_zero=False,
                   gps=True, home_far=True)


def _in(mode: FlightMode, **kw: bool) -> Situation:
    return dataclasses.replace(FLYING, mode=mode, **kw)  # no __dict__ on the compiled SITL


@pytest.mark.parametrize("mode", [FlightMode.STABILIZE, FlightMode.ALT_HOLD])
@pytest.mark.parametrize("action", [1, 2, 3, 4, 5])
def test_copter4_fs_options_16_continues_every_action_in_pilot_controlled_modes(
        mode: FlightMode, action: int) -> None:
    d = gcs_copter4(action, 16, _in(mode))
    assert d == (d.__class__(Response.NONE, "GCS Failsafe - Continuing Pilot Control"))


@pytest.mark.parametrize(("action", "gps", "want"), [
    (1, True, Response.RTL), (2, True, Response.RTL), (3, True, Response.SMART_RTL),
    (4, True, Response.SMART_RTL), (5, True, Response.LAND),
    (1, False, Response.LAND), (2, False, Response.LAND), (3, False, Response.LAND),
    (4, False, Response.LAND), (5, False, Response.LAND),
])
def test_copter4_fs_gcs_enable_actions_with_fs_options_0(action: int, gps: bool,
                                                         want: Response) -> None:
    d = gcs_copter4(action, 0, _in(FlightMode.ALT_HOLD, gps=gps))
    assert (d.response, d.text) == (want, "GCS Failsafe")


def test_copter4_disarms_on_the_floor_or_at_zero_throttle_in_stabilize() -> None:
    for s in (_in(FlightMode.STABILIZE, throttle_zero=True), _in(FlightMode.ALT_HOLD, landed=True),
              _in(FlightMode.LAND, landed=True)):
        d = gcs_copter4(5, 16, s)
        assert (d.response, d.text) == (Response.DISARM, "GCS Failsafe - Disarming")
    # ALT_HOLD at zero stick is not landed: that is a descent, not a reason to disarm
    assert gcs_copter4(5, 0, _in(FlightMode.ALT_HOLD, throttle_zero=True)).response is Response.LAND


def test_copter4_landing_and_disarmed_cases() -> None:
    # LAND is an autopilot mode: bit 4 does not keep it; FS_GCS_ENABLE 1 sends it to RTL
    assert gcs_copter4(1, 16, _in(FlightMode.LAND)).response is Response.RTL
    d = gcs_copter4(1, 8 | 16, _in(FlightMode.LAND))
    assert (d.response, d.text) == (Response.LAND, "GCS Failsafe - Continuing Landing")
    d = gcs_copter4(5, 16, _in(FlightMode.STABILIZE, armed=False))
    assert (d.response, d.text) == (Response.NONE, "GCS Failsafe")


def test_copter4_radio_failsafe_has_no_pilot_control_option() -> None:
    assert radio_copter4(1, 16, _in(FlightMode.STABILIZE)).response is Response.RTL
    assert radio_copter4(1, 16, _in(FlightMode.STABILIZE, gps=False)).response is Response.LAND
    assert radio_copter4(3, 16, _in(FlightMode.ALT_HOLD)).response is Response.LAND
    assert radio_copter4(1, 16, _in(FlightMode.ALT_HOLD)).text == "Radio Failsafe"


def test_apm25_gcs_failsafe_rtl_when_home_is_far_and_gps_else_land() -> None:
    assert gcs_apm25(FLYING) == gcs_apm25(FLYING).__class__(Response.RTL, None)
    assert gcs_apm25(_in(FlightMode.STABILIZE, home_far=False)).response is Response.LAND
    assert gcs_apm25(_in(FlightMode.STABILIZE, gps=False)).response is Response.LAND
    assert gcs_apm25(_in(FlightMode.STABILIZE, throttle_zero=True)).response is Response.DISARM
    # the land detector is not consulted: a landed, armed vehicle in LAND is sent to RTL
    assert gcs_apm25(_in(FlightMode.LAND, landed=True)).response is Response.RTL


def test_apm25_radio_failsafe() -> None:
    assert radio_apm25(1, FLYING).response is Response.RTL
    assert radio_apm25(3, FLYING).response is Response.LAND
    assert radio_apm25(1, _in(FlightMode.ALT_HOLD, landed=True)).response is Response.DISARM
    assert radio_apm25(1, _in(FlightMode.ALT_HOLD, gps=False)).response is Response.LAND
