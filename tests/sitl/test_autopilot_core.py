"""Pure pieces of the autopilot: mixer, throttle curves, PID, inertial nav, radio, failsafes."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from sitl.autopilot import Key, ParamStore, Profile
from sitl.autopilot.autopilot import Autopilot
from sitl.autopilot.failsafe import BATT_LOW_TIMER_S, GCS_TIMEOUT_S, BatteryWatch, GcsWatch
from sitl.autopilot.gains import Gains
from sitl.autopilot.inertial_nav import InertialNavZ
from sitl.autopilot.mixer import mix_plus
from sitl.autopilot.pid import Pid, PidGains
from sitl.autopilot.radio import Radio
from sitl.autopilot.throttle_curve import (
    climb_rate_from_stick,
    throttle_apm25,
    throttle_copter4,
)


def test_plus_mixer_signs_follow_arducopter_motor_order() -> None:
    # motor 1 right, 2 left, 3 front, 4 back
    roll = mix_plus(0.5, 0.2, 0.0, 0.0, 0.0).motors
    assert roll[0] < 0.5 < roll[1]  # roll right: right motor slows, left speeds up
    assert roll[2] == roll[3] == 0.5
    pitch = mix_plus(0.5, 0.0, 0.2, 0.0, 0.0).motors
    assert pitch[3] < 0.5 < pitch[2]  # nose up: front faster, back slower
    yaw = mix_plus(0.5, 0.0, 0.0, 0.2, 0.0).motors
    assert yaw[0] == yaw[1] > 0.5 > yaw[2] == yaw[3]  # yaw right: CCW props (1, 2) faster


def test_mixer_keeps_attitude_authority_at_full_throttle() -> None:
    out = mix_plus(1.0, 0.4, 0.0, 0.0, 0.1)
    m = out.motors
    assert out.limit_high
    assert max(m) <= 1.0
    assert m[1] - m[0] == pytest.approx(0.4)  # the full roll difference survives


def test_physics_order_is_front_right_back_left() -> None:
    out = mix_plus(0.5, 0.1, 0.2, 0.0, 0.0)
    m = out.motors
    assert out.physics_order() == (m[2], m[0], m[3], m[1])


def test_apm25_throttle_curve_passes_thr_mid_at_mid_stick() -> None:
    assert throttle_apm25(500.0, 450.0, 130.0) == pytest.approx(0.45)
    assert throttle_apm25(130.0, 450.0, 130.0) == pytest.approx(0.13)
    assert throttle_apm25(1000.0, 450.0, 130.0) == pytest.approx(1.0)
    assert throttle_apm25(0.0, 450.0, 130.0) == 0.0
    xs = [throttle_apm25(s, 450.0, 130.0) for s in range(0, 1001, 50)]
    assert xs == sorted(xs)


@pytest.mark.parametrize("hover", [0.3, 0.39, 0.5, 0.6])
def test_copter4_expo_curve_gives_hover_at_mid_stick(hover: float) -> None:
    assert throttle_copter4(500.0, hover) == pytest.approx(hover)
    assert throttle_copter4(0.0, hover) == 0.0
    assert throttle_copter4(1000.0, hover) == pytest.approx(1.0)
    xs = [throttle_copter4(s, hover) for s in range(0, 1001, 25)]
    assert all(b >= a for a, b in itertools.pairwise(xs))


def test_climb_rate_has_a_deadzone_and_full_scale() -> None:
    assert climb_rate_from_stick(500.0, 100.0, 250.0, 250.0) == 0.0
    assert climb_rate_from_stick(590.0, 100.0, 250.0, 250.0) == 0.0
    assert climb_rate_from_stick(1000.0, 100.0, 250.0, 250.0) == pytest.approx(250.0)
    assert climb_rate_from_stick(0.0, 100.0, 250.0, 250.0) == pytest.approx(-250.0)


def test_pid_integrator_is_clamped_and_recovers_from_windup() -> None:
    pid = Pid(PidGains(kp=1.0, ki=2.0, kd=0.0, imax=0.5))
    for _ in range(1000):
        pid.update(1.0, 0.01)
    assert pid.integrator == pytest.approx(0.5)
    steps = 0
    while pid.integrator > 0.0:
        pid.update(-1.0, 0.01)
        steps += 1
    assert steps <= 26  # 0.5 / (2.0 * 0.01) = 25 steps: no hidden windup beyond IMAX


def test_apm25_rate_gains_are_converted_from_centidegrees() -> None:
    p = ParamStore(Profile.APM25)
    g = Gains.from_params(p)
    assert g.rate_rll.kp == pytest.approx(0.15 * (18000.0 / math.pi) / 4500.0)
    assert g.rate_rll.imax == pytest.approx(1000.0 / 4500.0)
    assert g.angle_max_rad == pytest.approx(math.radians(45.0))
    c4 = Gains.from_params(ParamStore(Profile.COPTER4))
    assert c4.rate_rll.kp == pytest.approx(0.135)


def test_inertial_nav_learns_accel_bias_and_tracks_a_climb() -> None:
    rng = np.random.default_rng(4)
    nav = InertialNavZ(tc_z_s=5.0)
    dt = 0.01
    alt = vel = 0.0
    errs = []
    for k in range(8000):
        t = k * dt
        acc = 0.5 if 50.0 <= t < 52.0 else (-0.5 if 52.0 <= t < 54.0 else 0.0)
        vel += acc * dt
        alt += vel * dt
        if k % 10 == 0:
            nav.correct(alt + rng.normal(0.0, 0.1))
        nav.update(acc + 0.15 + rng.normal(0.0, 0.05), dt)  # biased accelerometer
        if t > 45.0:
            errs.append(nav.alt_m - alt)
    assert alt == pytest.approx(2.0, abs=0.05)
    assert nav._acc_corr == pytest.approx(-0.15, abs=0.03)  # the bias was learned
    assert float(np.max(np.abs(errs))) < 0.25  # through the climb, with 0.1 m baro noise


def test_radio_override_rules() -> None:
    r = Radio(Profile.APM25)
    assert r.channels()[2] == 1000  # the transmitter's throttle is at the bottom
    r.apply_override([1500, 1500, 1600, 1500, 0, 0, 0, 0], 0.0)
    assert r.channel(2) == 1600
    r.apply_override([65535, 65535, 65535, 65535, 0, 0, 0, 0], 1.0)
    assert r.channel(2) == 1600  # UINT16_MAX leaves a channel alone
    r.apply_override([0, 0, 0, 0, 0, 0, 0, 0], 2.0)
    assert r.channel(2) == 1000  # 0 releases it
    r.apply_override([1500, 1500, 2500, 1500, 0, 0, 0, 0], 3.0)
    assert r.channel(2) == 2000  # clamped to the radio's range
    assert not r.expire(100.0, 0.0)  # 3.2.1: no timeout
    assert r.channel(2) == 2000


def test_copter4_override_timeout_drops_to_radio() -> None:
    r = Radio(Profile.COPTER4)
    r.apply_override([1500, 1500, 1600, 1500, 0, 0, 0, 0], 10.0)
    assert not r.expire(12.9, 3.0)
    assert r.channel(2) == 1600
    assert r.expire(13.0, 3.0)
    assert r.channel(2) == 1000


def test_gcs_watch_needs_overrides_on_apm25_only() -> None:
    w = GcsWatch()
    assert w.check(100.0, requires_override=True, override_active=True) is None  # never seen
    w.seen(0.0)
    assert w.check(GCS_TIMEOUT_S + 0.1, requires_override=True, override_active=False) is None
    assert w.check(GCS_TIMEOUT_S + 0.1, requires_override=False, override_active=False) is True
    w.seen(10.0)
    assert w.check(10.0, requires_override=False, override_active=False) is False


def test_battery_watch_waits_for_the_low_timer() -> None:
    b = BatteryWatch()
    assert not b.check(0.0, 10.0, 10.5)
    assert not b.check(BATT_LOW_TIMER_S - 0.1, 10.0, 10.5)
    assert b.check(BATT_LOW_TIMER_S, 10.0, 10.5)
    assert not b.check(BATT_LOW_TIMER_S + 1.0, 10.0, 10.5)  # reported once


def test_param_store_rounds_integer_types_and_tracks_versions() -> None:
    p = ParamStore(Profile.APM25)
    v0 = p.version
    assert p.set("THR_MID", 450.7) == 451.0
    assert p.k(Key.THR_HOVER) == 451.0
    assert p.set("STB_RLL_P", 3.25) == 3.25
    assert p.version == v0 + 2
    assert "MOT_THST_HOVER" not in p
    assert "MOT_THST_HOVER" in ParamStore(Profile.COPTER4)
    assert ParamStore(Profile.COPTER4).name_of(Key.POS_Z_P) == "PSC_POSZ_P"
    assert p.name_of(Key.POS_Z_P) == "THR_ALT_P"


@pytest.mark.parametrize(("profile", "dz_us"), [(Profile.APM25, 30), (Profile.COPTER4, 20)])
def test_the_sticks_dead_zones_are_the_ones_the_vehicle_reports(profile: Profile,
                                                                 dz_us: int) -> None:
    """3.2.1 reports RC1_DZ/RC2_DZ 30 µs, 4.7 reports 20 (the fixtures' parameter lists) and
    each applies what it reports; a pilot's change of RC1_DZ takes effect too."""
    params = ParamStore(profile)
    ap = Autopilot(profile, params, 0.45)
    assert params.k(Key.RC1_DZ) == params.k(Key.RC2_DZ) == dz_us
    ap.radio.apply_override([1500 + dz_us, 1500 - dz_us - 1, 1000, 1500], 0.0)
    assert ap._angle(0) == 0.0 and ap._angle(1) < 0.0
    ap.radio.apply_override([1500 + dz_us + 1, 1500, 1000, 1500], 0.0)
    assert ap._angle(0) > 0.0
    params.set_key(Key.RC1_DZ, dz_us + 10)
    ap._refresh_gains()
    assert ap._angle(0) == 0.0
