"""The position loop's stick mapping follows the vehicle's ANGLE_MAX and RC1/RC2_DZ."""

from __future__ import annotations

import math

import pytest

from firmware_link.records import MocapPose
from gcs.control.position_controller import (
    PositionController,
    PositionControllerParams,
    PositionSetpoint,
    with_vehicle_sticks,
)

# as the fixtures' parameter lists have them
APM25 = {"ANGLE_MAX": 4500.0, "RC1_DZ": 30.0, "RC2_DZ": 30.0}
COPTER47 = {"ANGLE_MAX": 3000.0, "RC1_DZ": 20.0, "RC2_DZ": 20.0}


def vehicle_lean_deg(pwm: int, values: dict[str, float]) -> float:
    """What ArduCopter makes of a pitch stick: past the deadzone, linear to ANGLE_MAX."""
    dz = values["RC2_DZ"]
    off = abs(pwm - 1500) - dz
    return max(off, 0.0) / (500.0 - dz) * values["ANGLE_MAX"] / 100.0


@pytest.mark.parametrize("values", [APM25, COPTER47], ids=["3.2.1", "4.7"])
def test_the_vehicle_leans_as_much_as_the_loop_asks(values: dict[str, float]) -> None:
    params = with_vehicle_sticks(PositionControllerParams(), values)
    ctl = PositionController(params)
    pose = MocapPose(t_s=0.0, sysid=1, pos_n=(0.0, 0.0, -1.0), q_nb=(1.0, 0.0, 0.0, 0.0),
                     time_usec=0)
    for _ in range(10):  # the profile's acceleration ramps up over its first ticks
        cmd = ctl.update(PositionSetpoint(0.3, 0.0, 0.0), pose, 0.025)
    asked = math.degrees(abs(cmd.pitch_rad))
    assert asked > 1.0
    assert vehicle_lean_deg(cmd.pitch_us, values) == pytest.approx(asked, abs=0.1)


def test_the_old_fixed_mapping_would_lean_a_47_vehicle_two_thirds() -> None:
    ctl = PositionController(PositionControllerParams())  # 45° and 30 µs, 3.2.1's
    pose = MocapPose(t_s=0.0, sysid=1, pos_n=(0.0, 0.0, -1.0), q_nb=(1.0, 0.0, 0.0, 0.0),
                     time_usec=0)
    for _ in range(40):  # a far set point: the profile runs up to its full lean
        cmd = ctl.update(PositionSetpoint(5.0, 0.0, 0.0), pose, 0.025)
    leaned = vehicle_lean_deg(cmd.pitch_us, COPTER47)
    assert leaned < 0.75 * math.degrees(abs(cmd.pitch_rad))


def test_an_impossible_mapping_is_refused_in_one_line() -> None:
    with pytest.raises(ValueError, match="ANGLE_MAX 0"):
        with_vehicle_sticks(PositionControllerParams(), {**COPTER47, "ANGLE_MAX": 0.0})
