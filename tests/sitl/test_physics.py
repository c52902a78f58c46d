"""Physics of the simulated quadrotor: equilibrium, free fall, torque signs, contact, battery."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sitl import physics_state
from sitl.battery import battery_state, cell_ocv_v, terminal_voltage_v
from sitl.motors import max_speed_radps, thrust_n
from sitl.params import GRAVITY_MPS2, ParamError, VehicleParams
from sitl.rotation import quat_from_euler
from sitl.vehicle_model import SimVehicle
from sitl.world import Box, World, default_world

DT = 0.0025
REST_Z = -VehicleParams().gear_height_m


def make(z_m: float = 0.0, *, hovering: bool = False, world: World | None = None) -> SimVehicle:
    """A noise-free vehicle at the centre of the default room."""
    return SimVehicle(
        world or default_world(),
        start_pos_n=(0.0, 0.0, z_m),
        rng=np.random.default_rng(7),
        noise=False,
        start_hovering=hovering,
    )


def run(v: SimVehicle, cmd: list[float], seconds: float, dt: float = DT) -> None:
    for _ in range(round(seconds / dt)):
        v.step(cmd, dt)


def test_analytic_hover_throttle_holds_altitude_open_loop() -> None:
    v = make(-1.0, hovering=True)
    u = v.hover_throttle()
    assert 0.4 < u < 0.6  # ≈ 2:1 thrust-to-weight hovers near half throttle
    run(v, [u] * 4, 2.0)
    t = v.truth
    assert abs(t.pos_n[2] - -1.0) < 0.03
    assert abs(t.vel_n[2]) < 0.05
    assert max(abs(t.roll_rad), abs(t.pitch_rad), abs(t.yaw_rad)) < 1e-9
    assert not t.on_ground


def test_thrust_to_weight_is_about_two() -> None:
    p = VehicleParams()
    full = 4 * thrust_n(p, max_speed_radps(p, p.ref_voltage_v))
    assert 1.8 < full / p.weight_n < 2.3


def test_hover_throttle_from_the_ground_lifts_off_only_above_it() -> None:
    below, above = make(), make()
    u = below.hover_throttle()
    run(below, [u - 0.03] * 4, 2.0)
    run(above, [u + 0.05] * 4, 2.0)
    assert below.truth.on_ground and below.truth.pos_n[2] == REST_Z
    assert not above.truth.on_ground and above.truth.pos_n[2] < REST_Z - 0.2


def test_free_fall_matches_g_before_drag_matters() -> None:
    v = make(-2.0)
    assert not v.truth.on_ground
    run(v, [0.0] * 4, 0.3)
    t = v.truth
    assert t.pos_n[2] - -2.0 == pytest.approx(0.5 * GRAVITY_MPS2 * 0.3**2, rel=0.02)
    assert t.vel_n[2] == pytest.approx(GRAVITY_MPS2 * 0.3, rel=0.03)
    assert t.acc_n[2] == pytest.approx(GRAVITY_MPS2, rel=0.05)
    # The accelerometer measures no specific force in free fall (drag only).
    assert abs(v.imu().acc_b[2]) < 0.6


def _nudge(delta: tuple[float, float, float, float], seconds: float = 0.2) -> SimVehicle:
    v = make(-1.5, hovering=True)
    u = v.hover_throttle()
    run(v, [u + d for d in delta], seconds)
    return v


def test_more_front_thrust_pitches_nose_up() -> None:
    t = _nudge((0.05, 0.0, 0.0, 0.0)).truth
    assert t.omega_b[1] > 0.1 and t.pitch_rad > 0.01
    # One motor also adds yaw torque, so roll appears only as a small cross-coupling.
    assert abs(t.roll_rad) < 0.05 * t.pitch_rad


def test_more_back_thrust_pitches_nose_down() -> None:
    t = _nudge((0.0, 0.0, 0.05, 0.0)).truth
    assert t.pitch_rad < -0.01


def test_more_right_thrust_rolls_left() -> None:
    t = _nudge((0.0, 0.05, 0.0, 0.0)).truth
    assert t.omega_b[0] < -0.1 and t.roll_rad < -0.01
    assert abs(t.pitch_rad) < 0.05 * abs(t.roll_rad)


def test_more_left_thrust_rolls_right() -> None:
    t = _nudge((0.0, 0.0, 0.0, 0.05)).truth
    assert t.roll_rad > 0.01


def test_clockwise_pair_yaws_nose_left_counter_clockwise_pair_right() -> None:
    # Front/back spin clockwise seen from above: their reaction torque on the frame is
    # counter-clockwise seen from above, i.e. negative yaw in NED/FRD.
    cw = _nudge((0.05, 0.0, 0.05, 0.0), 0.5).truth
    ccw = _nudge((0.0, 0.05, 0.0, 0.05), 0.5).truth
    assert cw.omega_b[2] < -0.05 and cw.yaw_rad < 0.0
    assert ccw.omega_b[2] > 0.05 and ccw.yaw_rad > 0.0
    for t in (cw, ccw):
        assert abs(t.roll_rad) < 1e-6 and abs(t.pitch_rad) < 1e-6


def test_tilted_thrust_accelerates_toward_the_tilt() -> None:
    # Nose down (negative pitch) points thrust forward: accelerate north.
    v = make(-1.5, hovering=True)
    v.set_pose((0.0, 0.0, -1.5), quat_from_euler(0.0, -0.2, 0.0))
    u = v.hover_throttle()
    run(v, [u] * 4, 0.3)
    assert v.truth.vel_n[0] > 0.4 and abs(v.truth.vel_n[1]) < 1e-9


def test_motor_lag_is_first_order_50ms() -> None:
    p = VehicleParams()
    v = make(-1.0)
    run(v, [1.0] * 4, p.motor_lag_s)
    w = v.truth.motor_speed_radps[0]
    w_ss = max_speed_radps(p, v.battery.voltage_v)
    assert w / w_ss == pytest.approx(1.0 - math.exp(-1.0), abs=0.03)


def test_rests_on_floor_motors_off_without_drift_or_bounce() -> None:
    v = make()
    for _ in range(4000):  # 10 s
        v.step([0.0] * 4, DT)
        t = v.truth
        assert t.pos_n == (0.0, 0.0, REST_Z)
        assert t.vel_n == (0.0, 0.0, 0.0)
        assert t.on_ground
    assert v.imu().acc_b[2] == pytest.approx(-GRAVITY_MPS2, abs=0.001)


def test_rests_with_thrust_below_weight() -> None:
    v = make()
    run(v, [0.35] * 4, 5.0)
    t = v.truth
    assert t.pos_n == (0.0, 0.0, REST_Z) and t.vel_n == (0.0, 0.0, 0.0) and t.on_ground


def test_drop_lands_inelastically_and_never_bounces() -> None:
    v = make(-1.0)
    landed = False
    for _ in range(1200):
        v.step([0.0] * 4, DT)
        t = v.truth
        assert t.pos_n[2] <= REST_Z + 1e-12  # never sinks into the floor
        if landed:
            assert t.on_ground and t.pos_n[2] == REST_Z and t.vel_n[2] == 0.0
        landed = landed or t.on_ground
    assert landed


def test_friction_stops_a_sliding_landing() -> None:
    p = VehicleParams()
    world = default_world()
    s = physics_state.PhysicsState.at_rest(p, world, (0.0, 0.0, 0.0))
    s = dataclasses.replace(s, vel_n=np.array([1.0, 0.0, 0.0]))
    for _ in range(200):
        s = physics_state.step(s, [0.0] * 4, p, DT, world)
    assert s.vel_n[0] == 0.0
    stop = 1.0 / (2 * p.ground_friction * GRAVITY_MPS2)
    assert s.pos_n[0] == pytest.approx(stop, rel=0.05)


def test_pure_step_does_not_mutate_and_is_deterministic() -> None:
    p, world = VehicleParams(), default_world()
    s0 = physics_state.PhysicsState.at_rest(p, world, (0.0, 0.0, -1.0))
    a = physics_state.step(s0, [0.6, 0.5, 0.55, 0.5], p, 0.02, world)
    b = physics_state.step(s0, [0.6, 0.5, 0.55, 0.5], p, 0.02, world)
    assert s0.pos_n[2] == -1.0 and s0.vel_n[2] == 0.0
    np.testing.assert_array_equal(a.pos_n, b.pos_n)
    np.testing.assert_array_equal(a.q_nb, b.q_nb)


def test_large_step_is_split_into_400hz_substeps() -> None:
    one, many = make(-1.0, hovering=True), make(-1.0, hovering=True)
    cmd = [0.6, 0.5, 0.52, 0.5]
    one.step(cmd, 0.025)
    for _ in range(10):
        many.step(cmd, 0.0025)
    assert one.truth.pos_n == pytest.approx(many.truth.pos_n, abs=1e-12)
    assert one.truth.q_nb == pytest.approx(many.truth.q_nb, abs=1e-12)
    assert one.t_s == pytest.approx(0.025)


def test_quaternion_stays_unit_through_aggressive_rotation() -> None:
    v = make(-1.5, hovering=True)
    run(v, [0.9, 0.2, 0.3, 0.8], 0.5)
    q = v.truth.q_nb
    assert math.fsum(c * c for c in q) == pytest.approx(1.0, abs=1e-12)


def test_nan_and_out_of_range_throttles_are_clamped() -> None:
    v = make()
    run(v, [math.nan, -3.0, math.nan, -1.0], 0.5)
    assert v.truth.motor_speed_radps == (0.0, 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="motor_cmd"):
        v.step([0.5, 0.5, 0.5], DT)
    with pytest.raises(ValueError, match="dt_s"):
        v.step([0.5] * 4, 0.0)


def test_flying_into_a_wall_stops_there_and_names_it() -> None:
    p, world = VehicleParams(), default_world()
    v = make(-1.5, hovering=True)
    v.set_pose((2.0, 0.0, -1.5), vel_n=(3.0, 0.0, 0.0))
    u = v.hover_throttle()
    hit = None
    for _ in range(400):
        v.step([u] * 4, DT)
        t = v.truth
        assert t.pos_n[0] + p.body_radius_m <= world.room_max_n[0]  # no tunnelling
        hit = hit or t.collided_with
    assert hit == "wall_north"
    assert v.truth.vel_n[0] <= 1e-9
    assert v.truth.collisions == 1  # pressing on the wall afterwards is the same collision


def test_flying_into_a_box_names_it() -> None:
    world = World(boxes=(Box("crate", (1.0, -0.5, -2.0), (1.5, 0.5, 0.0)),))
    v = make(-1.0, hovering=True, world=world)
    v.set_pose((0.0, 0.0, -1.0), vel_n=(2.0, 0.0, 0.0))
    u = v.hover_throttle()
    names = set()
    for _ in range(400):
        v.step([u] * 4, DT)
        assert v.truth.pos_n[0] < 1.0 - VehicleParams().body_radius_m + 1e-9
        names.add(v.truth.collided_with)
    assert "crate" in names


def test_lands_and_rests_on_a_box_top() -> None:
    world = World(boxes=(Box("crate", (-0.5, -0.5, -0.4), (0.5, 0.5, 0.0)),))
    v = make(-1.0, world=world)
    run(v, [0.0] * 4, 1.5)
    t = v.truth
    assert t.on_ground and t.pos_n[2] == pytest.approx(-0.4 + REST_Z)
    assert t.collided_with is None


def test_battery_sags_under_load_and_runs_down() -> None:
    v = make()
    rest_v = v.battery.voltage_v
    run(v, [0.45] * 4, 2.0)  # below weight: stays on the floor but draws current
    loaded = v.battery
    assert loaded.current_a > 5.0
    assert loaded.voltage_v < rest_v - 0.2
    assert loaded.remaining_pct < 100.0
    p = VehicleParams()
    # Sag is I·R on top of the open-circuit voltage.
    assert loaded.voltage_v == pytest.approx(
        terminal_voltage_v(p, loaded.used_mah, loaded.current_a), abs=0.05
    )


def test_emptier_battery_means_less_thrust_and_higher_hover_throttle() -> None:
    p = VehicleParams()
    full = battery_state(p, 0.0, 20.0).voltage_v
    low = battery_state(p, 0.8 * p.battery_capacity_mah, 20.0).voltage_v
    assert low < full
    assert thrust_n(p, max_speed_radps(p, low)) < 0.85 * thrust_n(p, max_speed_radps(p, full))
    fresh = make(-1.0, hovering=True)
    tired = SimVehicle(
        default_world(),
        start_pos_n=(0.0, 0.0, -1.0),
        rng=np.random.default_rng(7),
        noise=False,
        start_hovering=True,
        battery_used_mah=0.8 * p.battery_capacity_mah,
    )
    assert tired.battery.remaining_pct == pytest.approx(20.0)
    assert tired.hover_throttle() > fresh.hover_throttle() + 0.03
    u = tired.hover_throttle()
    run(tired, [u] * 4, 1.0)
    assert abs(tired.truth.pos_n[2] - -1.0) < 0.03
    assert cell_ocv_v(1.0) == 4.2 and cell_ocv_v(0.0) < 3.4


def test_inertia_is_diagonal_plausible_and_masses_sum() -> None:
    p = VehicleParams()
    ixx, iyy, izz = p.inertia_kgm2
    assert ixx == iyy and 0.02 <= ixx <= 0.03
    assert 0.035 <= izz <= 0.045 and izz > ixx
    assert p.central_mass_kg + 4 * p.motor_mass_kg == pytest.approx(p.mass_kg)
    assert p.arm_length_m == pytest.approx(0.225)


def test_params_validate_and_load_from_toml() -> None:
    with pytest.raises(ParamError, match="mass_kg"):
        VehicleParams(mass_kg=-1.0)
    with pytest.raises(ParamError, match="motor_mass_kg"):
        VehicleParams(motor_mass_kg=0.5)
    with pytest.raises(ParamError, match="wingspan_m: unknown field"):
        VehicleParams.from_toml({"wingspan_m": 1.0})
    with pytest.raises(ParamError, match="mass_kg: expected a number"):
        VehicleParams.from_toml({"mass_kg": "heavy"})
    assert VehicleParams.from_toml({"mass_kg": 1.8}).mass_kg == 1.8


def test_sliding_off_a_box_edge_falls_to_the_floor() -> None:
    p = VehicleParams()
    world = World(boxes=(Box("crate", (-0.5, -0.5, -0.4), (0.5, 0.5, 0.0)),))
    s = physics_state.PhysicsState.at_rest(p, world, (0.4, 0.0, -0.4))
    assert s.on_ground and s.pos_n[2] == pytest.approx(-0.4 - p.gear_height_m)
    s = dataclasses.replace(s, vel_n=np.array([1.5, 0.0, 0.0]))
    for _ in range(400):
        s = physics_state.step(s, [0.0] * 4, p, DT, world)
    assert s.on_ground and s.pos_n[2] == pytest.approx(-p.gear_height_m)
    assert s.pos_n[0] > 0.5


@settings(max_examples=25, deadline=None)
@given(
    cmd=st.lists(st.floats(-0.5, 1.5) | st.just(math.nan), min_size=4, max_size=4),
    seconds=st.floats(0.05, 1.5),
)
def test_any_throttles_keep_the_state_sane(cmd: list[float], seconds: float) -> None:
    p, world = VehicleParams(), default_world()
    s = physics_state.PhysicsState.at_rest(p, world, (0.0, 0.0, -1.0))
    s = physics_state.step(s, cmd, p, seconds, world)
    assert np.all(np.isfinite(s.pos_n)) and np.all(np.isfinite(s.omega_b))
    assert float(np.dot(s.q_nb, s.q_nb)) == pytest.approx(1.0, abs=1e-9)
    assert s.pos_n[2] <= -p.gear_height_m + 1e-12  # never below the floor
    lo, hi = np.array(world.room_min_n), np.array(world.room_max_n)
    assert np.all(s.pos_n >= lo) and np.all(s.pos_n <= hi)
    assert 0.0 < s.voltage_v <= 12.6
