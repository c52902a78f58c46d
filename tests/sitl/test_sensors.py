"""Sensor realism: noise and bias bounds, saturation, timing, range limits, cones, counts."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sitl.params import GRAVITY_MPS2, VehicleParams
from sitl.rotation import quat_from_euler
from sitl.sensor_params import BaroParams, ImuParams, SonarParams
from sitl.sensors.baro import BaroModel, isa_altitude_m, isa_pressure_pa
from sitl.sensors.imu import ImuModel
from sitl.sensors.proximity import ProximityFacing
from sitl.sensors.radiation import RadiationModel
from sitl.sensors.sonar import SonarModel
from sitl.vehicle_model import SimVehicle
from sitl.world import Box, FloorMaterial, RadiationSource, World, default_world, load_world

WORLDS = Path(__file__).resolve().parents[2] / "worlds"
DT = 0.0025
GEAR = VehicleParams().gear_height_m


def vehicle(
    world: World | None = None,
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0),
    *,
    seed: int = 3,
    noise: bool = True,
    hovering: bool = False,
) -> SimVehicle:
    return SimVehicle(
        world or default_world(),
        start_pos_n=pos,
        rng=np.random.default_rng(seed),
        noise=noise,
        start_hovering=hovering,
    )


# --- IMU ----------------------------------------------------------------------------------


def _imu_series(v: SimVehicle, n: int, cmd: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    acc, gyro = [], []
    for _ in range(n):
        v.step([cmd] * 4, DT)
        s = v.imu()
        acc.append(s.acc_b)
        gyro.append(s.gyro_b)
    return np.array(acc), np.array(gyro)


def test_imu_at_rest_reads_minus_g_with_bounded_bias_and_noise() -> None:
    acc, gyro = _imu_series(vehicle(), 2000)
    mean, rms = acc.mean(axis=0), acc.std(axis=0)
    assert mean[2] == pytest.approx(-GRAVITY_MPS2, abs=0.16)
    assert np.all(np.abs(mean[:2]) <= 0.16)
    assert np.all(rms >= 0.05) and np.all(rms < 0.1)
    assert np.all(np.abs(gyro.mean(axis=0)) <= 0.011)
    assert np.all(gyro.std(axis=0) >= 0.005)


def test_imu_bias_is_constant_per_run_and_seeded() -> None:
    biases = []
    for seed in (1, 1, 2):
        acc, _ = _imu_series(vehicle(seed=seed), 1500)
        biases.append(acc.mean(axis=0) - (0.0, 0.0, -GRAVITY_MPS2))
    assert np.allclose(biases[0], biases[1])  # same seed, same run
    assert not np.allclose(biases[0], biases[2], atol=0.01)
    for b in biases:
        assert np.all(np.abs(b) <= 0.15 + 0.01)


def test_imu_vibration_grows_with_throttle() -> None:
    rest, _ = _imu_series(vehicle(), 800)
    v = vehicle(pos=(0.0, 0.0, -1.0), hovering=True)
    hover, _ = _imu_series(v, 800, cmd=v.hover_throttle())
    rms_rest = rest.std(axis=0)
    rms_hover = hover.std(axis=0)
    assert np.all(rms_hover >= 0.3)
    assert np.all(rms_hover > 3 * rms_rest)


def test_imu_counts_and_two_g_saturation() -> None:
    imu = ImuModel(ImuParams(), np.random.default_rng(0), noise=False)
    lsb = 2.0 * GRAVITY_MPS2 / 32768
    s = imu.sample(0.0, (0.0, 0.0, -GRAVITY_MPS2), (0.0, 0.0, 0.0), 0.0)
    assert s.acc_raw == (0, 0, -16384)
    assert s.acc_b[2] == pytest.approx(-GRAVITY_MPS2)
    s = imu.sample(0.0, (25.0, -40.0, 0.3), (10.0, -50.0, 0.01), 0.0)
    assert s.acc_raw[:2] == (32767, -32768)
    assert s.acc_b[0] == pytest.approx(32767 * lsb) and s.acc_b[0] < 2 * GRAVITY_MPS2
    assert s.acc_b[1] == pytest.approx(-2 * GRAVITY_MPS2)
    gyro_lsb = math.radians(2000.0) / 32768
    assert s.gyro_raw[0] == round(10.0 / gyro_lsb)
    assert s.gyro_raw[1] == -32768  # beyond ±2000 °/s
    assert all(isinstance(c, int) for c in s.acc_raw + s.gyro_raw)


def test_imu_in_tilted_flight_reads_thrust_along_body_z_only() -> None:
    # Thrust is the only non-gravity force (drag ~0 at first): f_b = (0, 0, -T/m) at any tilt.
    v = vehicle(pos=(0.0, 0.0, -1.5), noise=False, hovering=True)
    v.set_pose((0.0, 0.0, -1.5), quat_from_euler(0.15, -0.25, 0.4))
    u = v.hover_throttle()
    v.step([u] * 4, 0.01)
    s = v.imu()
    assert abs(s.acc_b[0]) < 0.02 and abs(s.acc_b[1]) < 0.02
    assert s.acc_b[2] == pytest.approx(-GRAVITY_MPS2, abs=0.05)  # hover thrust ≈ weight
    assert v.truth.vel_n[0] != 0.0  # ...while the vehicle accelerates sideways in NED


# --- sonar --------------------------------------------------------------------------------


def _sonar_readings(v: SimVehicle, seconds: float, cmd: float | None = None) -> list:
    out = []
    u = v.hover_throttle() if cmd is None else cmd
    for _ in range(round(seconds / DT)):
        v.step([u] * 4, DT)
        s = v.sonar()
        if s is not None:
            out.append(s)
    return out


def test_sonar_20hz_echo_delay_and_slant_range() -> None:
    v = vehicle(pos=(0.0, 0.0, -1.0), noise=False, hovering=True)
    readings = _sonar_readings(v, 2.0)
    assert 38 <= len(readings) <= 41
    offset = SonarParams().offset_down_m
    assert all(s.valid for s in readings)
    d = readings[-1].distance_m
    assert d == pytest.approx(-v.truth.pos_n[2] - offset, abs=0.002)
    # The reading arrives a round trip after its ping.
    assert readings[-1].t_s - readings[-1].ping_t_s == pytest.approx(2 * d / 340.0, abs=0.0026)
    # Tilted 30°: the beam along body z travels further to the floor.
    tilt = math.radians(30.0)
    v.set_pose((0.0, 0.0, -1.0), quat_from_euler(tilt, 0.0, 0.0))
    tilted = _sonar_readings(v, 0.1)
    expected = (1.0 - offset * math.cos(tilt)) / math.cos(tilt)
    assert tilted[-1].distance_m == pytest.approx(expected, abs=0.01)


def test_sonar_range_limits_on_ground_and_too_high() -> None:
    ground = _sonar_readings(vehicle(noise=False), 0.5, cmd=0.0)
    assert ground and all(not s.valid and s.distance_m == 0.0 for s in ground)
    high_world = load_world(WORLDS / "radiation_3src.toml")
    v = vehicle(high_world, pos=(0.0, 0.0, -4.5), noise=False, hovering=True)
    high = _sonar_readings(v, 0.5)
    assert high and all(not s.valid for s in high)
    assert high[0].t_s - high[0].ping_t_s == pytest.approx(SonarParams().timeout_s, abs=0.003)


def test_sonar_reads_the_top_of_a_box_below() -> None:
    world = World(boxes=(Box("crate", (-0.5, -0.5, -0.4), (0.5, 0.5, 0.0)),))
    v = vehicle(world, pos=(0.0, 0.0, -1.5), noise=False, hovering=True)
    d = _sonar_readings(v, 0.2)[-1].distance_m
    assert d == pytest.approx(1.5 - 0.4 - SonarParams().offset_down_m, abs=0.005)


def test_sonar_noise_and_outlier_statistics() -> None:
    prm = SonarParams()
    sonar = SonarModel(prm, np.random.default_rng(11), noise=True)
    values = []
    t = 0.0
    for _ in range(5000):
        t = sonar.next_ping_t_s
        sonar.ping(t, 1.5, FloorMaterial.HARD)
        s = sonar.poll(t + 0.1)
        assert s is not None
        values.append(s.distance_m)
    arr = np.array(values)
    inliers = arr[np.abs(arr - 1.5) < 0.1]
    outlier_share = 1.0 - inliers.size / arr.size
    assert 0.005 < outlier_share < 0.02
    assert 0.009 < inliers.std() < 0.012
    assert abs(inliers.mean() - 1.5) < 0.002
    assert sonar.poll(t + 0.2) is None  # each reading is handed out once


def test_carpet_gives_late_echoes_up_to_1_2_s_and_dropouts() -> None:
    world = load_world(WORLDS / "carpet_room.toml")
    carpet = vehicle(world, pos=(0.0, 0.0, -1.0), hovering=True, seed=5)
    hard = vehicle(world, pos=(2.0, 2.0, -1.0), hovering=True, seed=5)
    on_carpet = _sonar_readings(carpet, 20.0)
    on_hard = _sonar_readings(hard, 5.0)
    delays = np.array([s.t_s - s.ping_t_s for s in on_carpet if s.valid])
    assert delays.max() > 0.5 and delays.max() <= 1.2 + 0.03
    late, dropouts = carpet.sonar_stats
    assert late >= 5 and dropouts >= 5
    assert any(not s.valid for s in on_carpet)
    # Late echoes slow the reading rate well below 20 Hz.
    assert len(on_carpet) < 0.7 * 20 * 20
    hard_delays = [s.t_s - s.ping_t_s for s in on_hard if s.valid]
    assert max(hard_delays) < 0.01
    assert hard.sonar_stats == (0, 0)


# --- barometer ----------------------------------------------------------------------------


def test_baro_noise_and_pressure_at_height() -> None:
    v = vehicle(noise=True)
    alts, temps = [], []
    for _ in range(1000):
        v.step([0.0] * 4, DT)
        s = v.baro()
        alts.append(s.alt_m)
        temps.append(s.temperature_c)
    assert 0.1 <= float(np.std(alts)) < 0.2
    assert abs(float(np.mean(alts))) < 0.05  # zero at boot, no ground effect with motors off
    assert float(np.mean(temps)) == pytest.approx(25.0, abs=0.1)
    quiet = vehicle(pos=(0.0, 0.0, -2.0), noise=False, hovering=True)
    s = quiet.baro()
    start_amsl = default_world().origin.alt_amsl_m + 2.0
    assert s.pressure_pa == pytest.approx(isa_pressure_pa(start_amsl), abs=0.01)
    assert isa_altitude_m(isa_pressure_pa(123.0)) == pytest.approx(123.0, abs=1e-6)
    # 1 m higher is ≈ 12 Pa less pressure near sea level.
    assert isa_pressure_pa(60.0) - isa_pressure_pa(61.0) == pytest.approx(11.9, abs=0.3)


def test_baro_drift_over_ten_minutes() -> None:
    for seed in range(5):
        baro = BaroModel(BaroParams(), np.random.default_rng(seed))
        drift = [baro.drift_m(t) for t in np.arange(0.0, 600.0, 1.0)]
        assert max(drift) - min(drift) >= 0.2
        assert drift[0] == 0.0


def test_baro_ground_effect_near_the_floor_only() -> None:
    low = vehicle(pos=(0.0, 0.0, -(GEAR + 0.05)), noise=False, hovering=True)
    high = vehicle(pos=(0.0, 0.0, -1.5), noise=False, hovering=True)
    # alt_m is relative to the boot height, so compare to the true climb (zero here).
    assert low.baro().alt_m < -0.05
    assert high.baro().alt_m == pytest.approx(0.0, abs=1e-6)


# --- proximity ----------------------------------------------------------------------------


def _by_facing(v: SimVehicle) -> dict[ProximityFacing, float | None]:
    return {s.facing: s.distance_m for s in v.proximity()}


def test_proximity_nothing_in_the_middle_of_the_room() -> None:
    v = vehicle(pos=(0.0, 0.0, -1.5), noise=False, hovering=True)
    samples = v.proximity()
    assert [s.facing for s in samples] == [0, 2, 4, 6, 24, 25]
    assert all(s.distance_m is None and s.max_m == 0.5 for s in samples)


def test_proximity_wall_inside_cone_and_range_only() -> None:
    v = vehicle(pos=(2.7, 0.0, -1.5), noise=False, hovering=True)  # north wall at x = 3
    r = _by_facing(v)
    assert r[ProximityFacing.FRONT] == pytest.approx(0.3)
    assert all(r[f] is None for f in r if f != ProximityFacing.FRONT)
    # Yawed 45°: the cone's edge (22.5°) is the nearest ray to the wall at 0.45 m.
    v.set_pose((2.55, 0.0, -1.5), quat_from_euler(0.0, 0.0, math.radians(45.0)))
    front = _by_facing(v)[ProximityFacing.FRONT]
    assert front == pytest.approx(0.45 / math.cos(math.radians(22.5)), abs=1e-6)
    # Yawed 50°: the wall is outside the cone within 0.5 m.
    v.set_pose((2.55, 0.0, -1.5), quat_from_euler(0.0, 0.0, math.radians(50.0)))
    assert _by_facing(v)[ProximityFacing.FRONT] is None


def test_proximity_sees_table_above_and_box_below() -> None:
    world = load_world(WORLDS / "table_room.toml")
    v = vehicle(world, pos=(2.0, 0.0, -0.5), noise=False, hovering=True)
    samples = {s.facing: s for s in v.proximity()}
    up, down = samples[ProximityFacing.UP], samples[ProximityFacing.DOWN]
    assert up.target == "table_top" and up.distance_m == pytest.approx(0.22)
    assert down.target == "goal_box" and down.distance_m == pytest.approx(0.3)


def test_proximity_ignores_a_post_outside_every_cone() -> None:
    post = Box("post", (1.3, -0.05, -3.0), (1.4, 0.05, 0.0))
    world = World(boxes=(post,))
    v = vehicle(world, pos=(1.0, 0.0, -1.5), noise=False, hovering=True)
    assert _by_facing(v)[ProximityFacing.FRONT] == pytest.approx(0.3)
    v.set_pose((1.0, 0.32, -1.5))  # post at ≈ 45° off the front and left axes, ≈ 0.43 m
    assert all(d is None for d in _by_facing(v).values())


def test_proximity_sees_another_vehicle() -> None:
    v = vehicle(pos=(0.0, 0.0, -1.5), noise=False, hovering=True)
    samples = {s.facing: s for s in v.proximity(others_n=[(0.0, 0.6, -1.5)])}
    right = samples[ProximityFacing.RIGHT]
    assert right.target == "vehicle"
    assert right.distance_m == pytest.approx(0.6 - VehicleParams().body_radius_m)
    assert samples[ProximityFacing.LEFT].distance_m is None
    assert all(s.distance_m is None for s in v.proximity(others_n=[(0.0, 1.5, -1.5)]))


def test_proximity_noise() -> None:
    v = vehicle(pos=(2.7, 0.0, -1.5), hovering=True)
    values = [_by_facing(v)[ProximityFacing.FRONT] for _ in range(400)]
    arr = np.array(values, dtype=float)
    assert 0.01 <= arr.std() < 0.015
    assert arr.mean() == pytest.approx(0.3, abs=0.003)


# --- radiation ----------------------------------------------------------------------------


def test_radiation_poisson_mean_and_variance() -> None:
    world = load_world(WORLDS / "radiation_3src.toml")
    src = world.sources[0]
    model = RadiationModel(
        world.sources, world.background_cps, world.sensors.radiation, np.random.default_rng(4)
    )
    pos = (src.pos_n[0] + 1.0, src.pos_n[1], src.pos_n[2])
    expected = model.rate_cps(pos)
    others = expected - src.strength_cps - world.background_cps
    assert 0.0 < others < 0.03 * src.strength_cps  # other sources are far away
    window = 0.1
    rates = np.array([model.sample(pos, window) for _ in range(3000)])
    assert rates.mean() == pytest.approx(expected, rel=0.01)
    counts = rates * window
    assert counts.var() == pytest.approx(counts.mean(), rel=0.1)  # Poisson: var = mean
    assert np.all(counts == np.round(counts))


def test_radiation_inverse_square_softened_and_background() -> None:
    src = RadiationSource("s", (0.0, 0.0, 0.0), 1000.0)
    world = World(sources=(src,), background_cps=10.0)
    model = RadiationModel(world.sources, 10.0, world.sensors.radiation, np.random.default_rng(0))
    assert model.rate_cps((1.0, 0.0, 0.0)) == pytest.approx(1010.0)
    assert model.rate_cps((2.0, 0.0, 0.0)) == pytest.approx(10.0 + 1000.0 * 1.01 / 4.01)
    at_source = model.rate_cps((0.0, 0.0, 0.0))
    assert math.isfinite(at_source) and at_source == pytest.approx(10.0 + 1000.0 * 101.0)
    assert load_world(WORLDS / "radiation_3src.toml").background_cps >= 0.01 * 5000.0
    assert vehicle().radiation(0.1) is None  # no sources in the empty room
    with pytest.raises(ValueError, match="dt_s"):
        model.sample((1.0, 0.0, 0.0), 0.0)


# --- motion capture -----------------------------------------------------------------------


def test_mocap_100hz_delayed_noisy_poses() -> None:
    v = vehicle(pos=(0.5, -0.5, -1.0), hovering=True, seed=9)
    u = v.hover_throttle()
    got = []
    for _ in range(400):
        v.step([u] * 4, DT)
        while (m := v.mocap()) is not None:
            assert m.delivered_t_s <= v.t_s + 1e-9
            got.append(m)
    assert 97 <= len(got) <= 100
    assert all(m.delivered_t_s - m.t_s >= 0.010 for m in got)
    stamps = np.array([m.t_s for m in got])
    assert np.allclose(np.diff(stamps), 0.01, atol=1e-6)
    xs = np.array([m.pos_n[0] for m in got])
    assert 0.0015 <= xs.std() <= 0.003 and xs.mean() == pytest.approx(0.5, abs=0.001)
    assert all(abs(math.fsum(c * c for c in m.q_nb) - 1.0) < 1e-9 for m in got)


def test_mocap_off_in_world_gives_nothing() -> None:
    v = vehicle(World(mocap_enabled=False))
    v.step([0.0] * 4, 0.1)
    assert v.mocap() is None
