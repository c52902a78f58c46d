"""The accelerometer reads the specific force averaged over the autopilot's loop period, so an
impact inside any physics sub-step reaches it (the MPU-6050's DLPF and ArduPilot's averaging)."""

from __future__ import annotations

import numpy as np
import pytest

from sitl.params import GRAVITY_MPS2, VehicleParams
from sitl.vehicle_model import SimVehicle
from sitl.world import default_world

LOOP_DT_S = 0.01  # the SITL autopilot's 100 Hz loop: four 2.5 ms physics sub-steps
REST_Z = -VehicleParams().gear_height_m


def _dropped(height_m: float) -> SimVehicle:
    return SimVehicle(
        default_world(),
        start_pos_n=(0.0, 0.0, REST_Z - height_m),
        rng=np.random.default_rng(11),
        noise=False,
    )


@pytest.mark.parametrize("height_m", [0.0020, 0.0030, 0.0045, 0.0060, 0.0080])
def test_a_floor_impact_in_any_sub_step_reaches_the_accelerometer(height_m: float) -> None:
    v = _dropped(height_m)
    readings, landed_at = [], None
    for k in range(20):
        vz_before = v.truth.vel_n[2]
        v.step([0.0] * 4, LOOP_DT_S)
        f_z = v.imu().acc_b[2]
        readings.append(f_z)
        if landed_at is None and v.truth.on_ground:
            landed_at = k
            # the mean over the step is exactly Δv/dt − g (level, noise off), below saturation
            expected = (v.truth.vel_n[2] - vz_before) / LOOP_DT_S - GRAVITY_MPS2
            assert f_z == pytest.approx(max(expected, -2.0 * GRAVITY_MPS2), abs=0.01)
    assert landed_at is not None and landed_at > 0
    assert all(abs(f) < 0.05 for f in readings[:landed_at])  # free fall (and drag)
    # the stop pushes up harder than gravity alone during the step it happens in
    assert readings[landed_at] < -1.2 * GRAVITY_MPS2
    assert readings[-1] == pytest.approx(-GRAVITY_MPS2, abs=0.01)  # then at rest


def test_teleport_reads_the_instantaneous_value_until_the_next_step() -> None:
    v = _dropped(0.5)
    v.step([0.0] * 4, LOOP_DT_S)
    assert v.imu().acc_b[2] == pytest.approx(0.0, abs=0.01)
    v.set_pose((0.0, 0.0, REST_Z))
    v.step([0.0] * 4, LOOP_DT_S)
    assert v.imu().acc_b[2] == pytest.approx(-GRAVITY_MPS2, abs=0.01)
