"""The horizontal loop on a modelled vehicle whose own lean estimate drifts as a real one does.

The model (one axis, north): ArduCopter holds its *estimated* pitch at the stick's angle past
the 30 µs deadzone, 0.05 s late with a 0.18 s lag (as fitted to the bundled SITL); without GPS
its estimate levels on the accelerometer, which reads along the body while the vehicle
accelerates, so the true lean runs ahead of the estimate by δ with dδ/dt = 0.5 rad/s · θ_est
(DCM's proportional gain). Motion capture sees the true pose; ATTITUDE reports the estimate.
"""

from __future__ import annotations

import math
from collections import deque

import pytest

from firmware_link.records import MocapPose
from gcs.control.attitude import lean_accel
from gcs.control.axis_filters import AlphaBeta, SetpointProfile
from gcs.control.position_controller import PositionController, PositionSetpoint
from gcs.estimation import GRAVITY_MPS2

DT = 0.025
ANGLE_MAX = math.radians(45.0)
DZ_US = 30


class Vehicle:
    """North axis of a hovering quadrotor flown by pitch stick (model in the module doc)."""

    def __init__(self, ahrs_kp: float = 0.5, offset_rad: float = 0.0) -> None:
        self.n = self.v = 0.0
        self.est = 0.0  # the autopilot's pitch estimate, which it holds at the stick's angle
        self.offset = offset_rad  # true pitch - estimate
        self.ahrs_kp = ahrs_kp
        self.sticks: deque[float] = deque([0.0, 0.0], maxlen=2)  # 0.05 s late
        self.t_usec = 0

    def pose(self) -> MocapPose:
        th = self.est + self.offset
        q = (math.cos(th / 2), 0.0, math.sin(th / 2), 0.0)
        return MocapPose(self.t_usec * 1e-6, 1, (self.n, 0.0, -1.0), q, self.t_usec)

    def step(self, pitch_us: int) -> None:
        d = pitch_us - 1500
        target = 0.0 if abs(d) <= DZ_US else math.copysign(abs(d) - DZ_US, d) / (500 - DZ_US)
        self.sticks.append(target * ANGLE_MAX)
        for _ in range(5):  # 5 ms inner steps
            h = DT / 5
            self.est += (self.sticks[0] - self.est) * h / 0.18
            self.offset += self.ahrs_kp * self.est * h
            a = -GRAVITY_MPS2 * math.tan(self.est + self.offset)  # nose down flies north
            self.v += a * h
            self.n += self.v * h
        self.t_usec += round(DT * 1e6)


def fly(setpoint_n: float, seconds: float, vehicle: Vehicle, pc: PositionController,
        report_lean: bool = True) -> list[tuple[float, float]]:
    """(time, north) each tick while holding `setpoint_n`."""
    track = []
    for k in range(round(seconds / DT)):
        lean = (0.0, vehicle.est) if report_lean else None
        cmd = pc.update(PositionSetpoint(setpoint_n, 0.0, 0.0), vehicle.pose(), DT, lean)
        vehicle.step(cmd.pitch_us)
        track.append(((k + 1) * DT, vehicle.n))
    return track


def test_a_lean_offset_is_measured_and_taken_out_not_flown() -> None:
    # the vehicle believes itself level while truly pitched 1° nose down (0.17 m/s² north)
    vehicle = Vehicle(ahrs_kp=0.0, offset_rad=math.radians(-1.0))
    pc = PositionController()
    track = fly(0.0, 8.0, vehicle, pc)
    # it barely got going (the offset is there from the first tick, its measure after
    # 0.1 s of smoothing and the lean's lag) and came back
    assert max(abs(n) for _t, n in track) < 0.03
    assert all(abs(n) < 0.003 for t, n in track if t > 6.0)
    cmd = pc.update(PositionSetpoint(0.0, 0.0, 0.0), vehicle.pose(), DT, (0.0, vehicle.est))
    assert math.degrees(cmd.lean_offset_pitch_rad) == pytest.approx(-1.0, abs=0.05)
    assert abs(cmd.i_n_mps2) < 0.02  # the integrator was not needed for it


def test_without_the_vehicles_lean_the_integrator_takes_a_constant_offset() -> None:
    vehicle = Vehicle(ahrs_kp=0.0, offset_rad=math.radians(-1.0))
    pc = PositionController()
    track = fly(0.0, 12.0, vehicle, pc, report_lean=False)
    assert max(abs(n) for _t, n in track) < 0.1
    assert all(abs(n) < 0.01 for t, n in track if t > 8.0)  # held in the end
    gain = -GRAVITY_MPS2 * math.tan(math.radians(-1.0))  # what the integrator had to learn
    assert pc.update(PositionSetpoint(0.0, 0.0, 0.0), vehicle.pose(), DT).i_n_mps2 \
        == pytest.approx(-gain, abs=0.02)


def overshoot_and_settle(track: list[tuple[float, float]], target: float) -> tuple[float, float]:
    past = max(n - target for _t, n in track) / target
    settle = next(t for i, (t, _n) in enumerate(track)
                  if all(abs(n - target) <= 0.05 for _t, n in track[i:]))
    return 100.0 * max(past, 0.0), settle


@pytest.mark.parametrize("leg_m", [0.5, 2.0])
def test_a_leg_meets_the_mission_floors_on_a_drifting_estimate(leg_m: float) -> None:
    vehicle = Vehicle()
    pc = PositionController()
    fly(0.0, 2.0, vehicle, pc)
    overshoot, settle = overshoot_and_settle(fly(leg_m, 8.0, vehicle, pc), leg_m)
    assert overshoot <= 10.0
    assert settle <= (2.0 if leg_m <= 0.5 else 4.0)
    # flown on its own lean estimate, the same vehicle ends the leg short or past the spot
    # and creeps in: the offset is what held the old loop's legs 5-15 cm off
    blind = Vehicle()
    pc = PositionController()
    fly(0.0, 2.0, blind, pc, report_lean=False)
    _, blind_settle = overshoot_and_settle(fly(leg_m, 8.0, blind, pc, report_lean=False), leg_m)
    assert blind_settle > settle + 0.5


def test_the_profile_brakes_in_time_and_lands_on_a_moving_target() -> None:
    prof = SetpointProfile(1.0, 1.5, 0.0)
    peak = 0.0
    for _ in range(200):
        prof.step(2.0, DT)
        peak = max(peak, prof.pos_m)
    assert prof.pos_m == 2.0 and prof.vel_mps == 0.0 and peak == 2.0
    for _ in range(20):  # turned round mid-move: it brakes, then comes back
        prof.step(-1.0, DT)
    assert prof.vel_mps < 0.0
    for _ in range(300):
        prof.step(-1.0, DT)
    assert prof.pos_m == -1.0


def test_the_observer_follows_a_ramp_without_lag_when_given_the_acceleration() -> None:
    aided, bare = AlphaBeta(3.0, 0.0), AlphaBeta(3.0, 0.0)
    n = v = 0.0
    for _ in range(40):  # 1 s at 1.5 m/s²
        v += 1.5 * DT
        n += v * DT
        aided.fix(n, DT, 1.5)
        bare.fix(n, DT)
    assert aided.vel_mps == pytest.approx(v, abs=0.03)
    assert v - bare.vel_mps > 0.1  # differencing alone lags by ~0.1 s at 3 Hz


def test_a_lean_gives_the_acceleration_of_a_weight_carrying_thrust() -> None:
    th = math.radians(-10.0)  # nose down: north
    a_n, a_e = lean_accel((math.cos(th / 2), 0.0, math.sin(th / 2), 0.0))
    assert a_n == pytest.approx(GRAVITY_MPS2 * math.tan(math.radians(10.0)))
    assert a_e == pytest.approx(0.0, abs=1e-12)
    ph = math.radians(5.0)  # roll right: east
    _, a_e = lean_accel((math.cos(ph / 2), math.sin(ph / 2), 0.0, 0.0))
    assert a_e == pytest.approx(GRAVITY_MPS2 * math.tan(ph))
