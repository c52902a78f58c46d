"""The physics as a pure function of numpy snapshots: `PhysicsState` and `step`.

The hot path (`sitl.vehicle_model`) keeps a mutable `sitl.physics.Core` and never builds these;
they are for callers that want values, not a shared object (tests, tools).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sitl.geometry import geometry
from sitl.params import VehicleParams
from sitl.physics import Core, initial_core, run
from sitl.rotation import quat_to_euler
from sitl.world import World


@dataclass(frozen=True)
class PhysicsState:
    """Rigid body + motors + battery, as numpy arrays (NED, FRD, q_nb = w, x, y, z)."""

    pos_n: np.ndarray  # m
    vel_n: np.ndarray  # m/s
    acc_n: np.ndarray  # m/s², over the last step (what an ideal accelerometer integrates)
    q_nb: np.ndarray  # unit quaternion, body to NED
    omega_b: np.ndarray  # rad/s, body rates p, q, r
    motor_speed_radps: np.ndarray  # (front, right, back, left)
    used_mah: float = 0.0
    current_a: float = 0.0
    voltage_v: float = 0.0
    on_ground: bool = False
    collided_with: str | None = None
    collisions: int = 0

    @staticmethod
    def at_rest(
        prm: VehicleParams, world: World, pos_n: Sequence[float], yaw_rad: float = 0.0
    ) -> PhysicsState:
        """Motors stopped, full battery, resting on the surface below pos_n (or in the air)."""
        c = initial_core(prm, world, pos_n, yaw_rad)
        return to_state(c)

    def euler_rad(self) -> tuple[float, float, float]:
        """(roll, pitch, yaw)."""
        w, x, y, z = (float(v) for v in self.q_nb)
        return quat_to_euler((w, x, y, z))


def to_state(c: Core) -> PhysicsState:
    """Snapshot of a Core as a PhysicsState."""
    return PhysicsState(
        pos_n=np.array([c.x, c.y, c.z]),
        vel_n=np.array([c.vx, c.vy, c.vz]),
        acc_n=np.array([c.ax, c.ay, c.az]),
        q_nb=np.array([c.qw, c.qx, c.qy, c.qz]),
        omega_b=np.array([c.p, c.q, c.r]),
        motor_speed_radps=np.array([c.m0, c.m1, c.m2, c.m3]),
        used_mah=c.used_mah,
        current_a=c.current_a,
        voltage_v=c.voltage_v,
        on_ground=c.on_ground,
        collided_with=c.collided_with,
        collisions=c.collisions,
    )


def from_state(s: PhysicsState) -> Core:
    """A Core holding the values of s."""
    c = Core()
    c.x, c.y, c.z = (float(v) for v in s.pos_n)
    c.vx, c.vy, c.vz = (float(v) for v in s.vel_n)
    c.ax, c.ay, c.az = (float(v) for v in s.acc_n)
    c.qw, c.qx, c.qy, c.qz = (float(v) for v in s.q_nb)
    c.p, c.q, c.r = (float(v) for v in s.omega_b)
    c.m0, c.m1, c.m2, c.m3 = (float(v) for v in s.motor_speed_radps)
    c.used_mah, c.current_a, c.voltage_v = s.used_mah, s.current_a, s.voltage_v
    c.on_ground, c.collided_with, c.collisions = s.on_ground, s.collided_with, s.collisions
    return c


def step(
    state: PhysicsState,
    motor_cmd: Sequence[float],
    params: VehicleParams,
    dt_s: float,
    world: World,
) -> PhysicsState:
    """Pure step: the state dt_s later under throttles motor_cmd (front, right, back, left)."""
    c = from_state(state)
    run(c, motor_cmd, params, geometry(world), dt_s)
    return to_state(c)
