"""One simulated quadrotor: physics, battery and every sensor, on a simulated clock.

`step()` advances physics in sub-steps of at most 2.5 ms (400 Hz) and runs the timed sensors
(sonar pings, motion-capture captures) on that clock; the other sensors are sampled when asked.
All randomness comes from the injected Generator, split into one child stream per sensor so that
reading one sensor more often never changes another's noise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sitl import physics
from sitl.battery import (
    BatteryState,
    battery_state,
    cell_ocv_v,
    state_of_charge,
    terminal_voltage_v,
)
from sitl.geometry import FLOOR, geometry
from sitl.motors import clamp_throttle, throttle_for_fraction
from sitl.params import GRAVITY_MPS2, VehicleParams, derived
from sitl.rotation import Quat, Vec3, quat_normalize, quat_to_euler, rotate_n_to_b
from sitl.sensors.baro import BaroModel, BaroSample
from sitl.sensors.imu import ImuModel, ImuSample
from sitl.sensors.mocap import MocapModel, MocapSample
from sitl.sensors.proximity import ProximityModel, ProximitySample
from sitl.sensors.radiation import RadiationModel
from sitl.sensors.sonar import SonarModel, SonarSample
from sitl.tick_record import tick_record
from sitl.world import FloorMaterial, World

OTHER_VEHICLE = "vehicle"  # proximity target name for another vehicle's body


@tick_record
class TruthState:
    """Ground truth (NED, FRD, q_nb = w, x, y, z); for evaluation, never for control."""

    t_s: float
    pos_n: Vec3
    vel_n: Vec3
    acc_n: Vec3
    q_nb: Quat
    omega_b: Vec3
    roll_rad: float
    pitch_rad: float
    yaw_rad: float
    on_ground: bool
    motor_speed_radps: tuple[float, float, float, float]  # front, right, back, left
    collided_with: str | None  # obstacle touched in the last step, None when clear
    collisions: int  # contacts begun at >= 0.1 m/s since the start

    @property
    def alt_m(self) -> float:
        """Height up: −z."""
        return -self.pos_n[2]


class SimVehicle:
    """A quadrotor in a world, stepped by throttles (front, right, back, left), 0..1."""

    def __init__(
        self,
        world: World,
        *,
        rng: np.random.Generator,
        params: VehicleParams | None = None,
        start_pos_n: Sequence[float] | None = None,
        yaw_rad: float = 0.0,
        noise: bool = True,
        start_hovering: bool = False,
        battery_used_mah: float = 0.0,
    ) -> None:
        """Place the vehicle at start_pos_n (default: the world's first start position).

        A start at or below the resting height puts it on whatever is below, motors stopped.
        `start_hovering` spins the motors at hover speed, for tests that start in the air.
        `params` defaults to the world's `[vehicle]` table; `battery_used_mah` starts the
        battery partly discharged.
        """
        self.world = world
        self.params = params if params is not None else world.vehicle
        self.noise = noise
        self._geom = geometry(world)
        pos = tuple(start_pos_n) if start_pos_n is not None else world.start_positions_n[0]
        if len(pos) != 3 or not all(math.isfinite(float(v)) for v in pos):
            raise ValueError(f"start_pos_n: expected 3 finite numbers, got {pos!r}")
        self._core = physics.initial_core(self.params, world, pos, yaw_rad)
        if not 0.0 <= battery_used_mah <= self.params.battery_capacity_mah:
            raise ValueError(
                f"battery_used_mah: expected 0..{self.params.battery_capacity_mah}, "
                f"got {battery_used_mah!r}"
            )
        c0 = self._core
        c0.used_mah = float(battery_used_mah)
        c0.voltage_v = terminal_voltage_v(self.params, c0.used_mah, c0.current_a)
        self.t_s = 0.0
        self._f_b_mean: Vec3 | None = None  # specific force averaged over the last step
        self._truth: TruthState | None = None  # built on the first look after a step
        self._substep: physics.SubStep | None = None  # constants of the last step's sub-steps
        s = world.sensors
        r_imu, r_sonar, r_baro, r_prox, r_rad, r_mocap = rng.spawn(6)
        self._imu = ImuModel(s.imu, r_imu, noise)
        self._sonar = SonarModel(s.sonar, r_sonar, noise)
        self._baro = BaroModel(
            s.baro, r_baro, noise, origin_alt_amsl_m=world.origin.alt_amsl_m - self._core.z
        )
        self._baro_z0 = self._core.z
        self._prox = ProximityModel(s.proximity, r_prox, noise)
        self._rad = RadiationModel(world.sources, world.background_cps, s.radiation, r_rad, noise)
        self._mocap = MocapModel(s.mocap, r_mocap, noise) if world.mocap_enabled else None
        if self._mocap is not None:
            c = self._core
            self._mocap.capture(0.0, (c.x, c.y, c.z), (c.qw, c.qx, c.qy, c.qz))
        if start_hovering:
            omega, volts, amps = self._hover_point()
            c = self._core
            c.m0 = c.m1 = c.m2 = c.m3 = omega
            c.voltage_v, c.current_a = volts, amps

    # --- time ---------------------------------------------------------------------------

    def step(self, motor_cmd: Sequence[float], dt_s: float) -> None:
        """Advance dt_s under throttles (front, right, back, left); sub-steps of ≤ 2.5 ms."""
        if not (dt_s > 0.0 and math.isfinite(dt_s)):
            raise ValueError(f"dt_s: expected a finite number > 0, got {dt_s!r}")
        if len(motor_cmd) != 4:
            raise ValueError(
                f"motor_cmd: expected 4 throttles (front, right, back, left), got {len(motor_cmd)}"
            )
        u0, u1, u2, u3 = (clamp_throttle(v) for v in motor_cmd)
        prm, geom, c = self.params, self._geom, self._core
        n = max(1, math.ceil(dt_s / prm.max_dt_s - 1e-9))
        h = dt_s / n
        k = self._substep
        if k is None or k.dt != h or k.prm is not prm:
            k = self._substep = physics.sub_step(prm, h)
        # the throttles hold over the whole step: their steady rotor speeds are worked out once
        speed = k.speed_fraction
        f0, f1, f2, f3 = speed(u0), speed(u1), speed(u2), speed(u3)
        t0 = self.t_s
        sonar, mocap = self._sonar, self._mocap
        advance = physics.advance_at
        sfx = sfy = sfz = 0.0
        for i in range(1, n + 1):
            advance(c, f0, f1, f2, f3, k, geom)
            # rotate_n_to_b(q, (ax, ay, az - g)) written out (same operations, same order):
            # the call and its tuples cost more than the arithmetic at 400 Hz
            w, x, y, z = c.qw, -c.qx, -c.qy, -c.qz
            vx, vy, vz = c.ax, c.ay, c.az - GRAVITY_MPS2
            tx = 2.0 * (y * vz - z * vy)
            ty = 2.0 * (z * vx - x * vz)
            tz = 2.0 * (x * vy - y * vx)
            sfx += vx + w * tx + (y * tz - z * ty)
            sfy += vy + w * ty + (z * tx - x * tz)
            sfz += vz + w * tz + (x * ty - y * tx)
            t = t0 + i * h
            if t >= sonar.next_ping_t_s:
                rng_m, surface = self._sonar_range()
                sonar.ping(t, rng_m, surface)
            if mocap is not None and t >= mocap.next_capture_t_s - 1e-9:
                mocap.capture(t, (c.x, c.y, c.z), (c.qw, c.qx, c.qy, c.qz))
        self.t_s = t0 + dt_s
        self._f_b_mean = (sfx / n, sfy / n, sfz / n)
        self._truth = None

    def set_pose(
        self,
        pos_n: Sequence[float],
        q_nb: Sequence[float] = (1.0, 0.0, 0.0, 0.0),
        vel_n: Sequence[float] = (0.0, 0.0, 0.0),
    ) -> None:
        """Teleport: put the vehicle at pos_n with attitude q_nb and velocity vel_n (rates zero).

        For tests and scenario resets; the next step() decides contact from the new pose.
        """
        vals = [float(v) for v in (*pos_n, *q_nb, *vel_n)]
        if len(vals) != 10 or not all(math.isfinite(v) for v in vals):
            raise ValueError("set_pose: expected pos_n (3), q_nb (4), vel_n (3) finite numbers")
        c = self._core
        c.x, c.y, c.z = vals[0:3]
        c.qw, c.qx, c.qy, c.qz = quat_normalize(*vals[3:7])
        c.vx, c.vy, c.vz = vals[7:10]
        c.p = c.q = c.r = 0.0
        rest_z = self._geom.support_z(c.x, c.y, c.z) - self.params.gear_height_m
        c.on_ground = c.z >= rest_z
        if c.on_ground:
            c.z = rest_z
        self._f_b_mean = None
        self._truth = None

    # --- truth and power ----------------------------------------------------------------

    @property
    def truth(self) -> TruthState:
        """Ground truth now (one object per step: the simulation and the truth feed both look)."""
        if self._truth is not None:
            return self._truth
        c = self._core
        q = (c.qw, c.qx, c.qy, c.qz)
        roll, pitch, yaw = quat_to_euler(q)
        self._truth = TruthState(
            t_s=self.t_s,
            pos_n=(c.x, c.y, c.z),
            vel_n=(c.vx, c.vy, c.vz),
            acc_n=(c.ax, c.ay, c.az),
            q_nb=q,
            omega_b=(c.p, c.q, c.r),
            roll_rad=roll,
            pitch_rad=pitch,
            yaw_rad=yaw,
            on_ground=c.on_ground,
            motor_speed_radps=(c.m0, c.m1, c.m2, c.m3),
            collided_with=c.collided_with,
            collisions=c.collisions,
        )
        return self._truth

    @property
    def battery(self) -> BatteryState:
        """Terminal voltage, current and charge left."""
        c = self._core
        return battery_state(self.params, c.used_mah, c.current_a)

    def _hover_point(self) -> tuple[float, float, float]:
        """(rotor speed, terminal volts, amps) at hover with the present charge."""
        prm = self.params
        d = derived(prm)
        omega = math.sqrt(prm.weight_n / (4.0 * d.k_thrust))
        ocv = prm.battery_cells * cell_ocv_v(state_of_charge(prm, self._core.used_mah))
        shaft_w = 4.0 * d.k_torque * omega**3
        volts, amps = ocv, prm.avionics_current_a
        for _ in range(30):  # fixed point V = OCV − I(V)·R; contracts fast (I·R ≪ V)
            amps = prm.avionics_current_a + shaft_w / (prm.motor_efficiency * max(volts, 0.5))
            volts = max(ocv - amps * prm.battery_resistance_ohm, 0.0)
        return omega, volts, amps

    def hover_throttle(self) -> float:
        """Throttle (0..1, all four motors) that holds altitude at the present battery charge."""
        prm = self.params
        omega, volts, _ = self._hover_point()
        wmax = derived(prm).omega_max_ref_radps * volts / prm.ref_voltage_v
        if wmax <= 0.0:
            return 1.0
        return throttle_for_fraction((omega / wmax) ** 2, prm.thrust_expo)

    # --- sensors ------------------------------------------------------------------------

    def _rotor_speed_frac(self) -> float:
        c = self._core
        return (c.m0 + c.m1 + c.m2 + c.m3) / (4.0 * derived(self.params).omega_max_ref_radps)

    def imu(self) -> ImuSample:
        """MPU-6050 reading now: specific force (a − g) averaged over the last step, body rates.

        The average over the step (the autopilot's loop period) stands for the MPU-6050's
        low-pass filter and ArduPilot's averaging of the samples between two loops: a floor or
        ceiling impact inside any sub-step reaches the accelerometer, not only one in the last.
        Before the first step (or after a teleport) it is the instantaneous value.
        """
        c = self._core
        f_b = self._f_b_mean
        if f_b is None:
            f_b = rotate_n_to_b((c.qw, c.qx, c.qy, c.qz), (c.ax, c.ay, c.az - GRAVITY_MPS2))
        return self._imu.sample(self.t_s, f_b, (c.p, c.q, c.r), self._rotor_speed_frac())

    def _sonar_range(self) -> tuple[float | None, FloorMaterial]:
        c = self._core
        bzx = 2.0 * (c.qx * c.qz + c.qw * c.qy)
        bzy = 2.0 * (c.qy * c.qz - c.qw * c.qx)
        bzz = 1.0 - 2.0 * (c.qx * c.qx + c.qy * c.qy)
        off = self.world.sensors.sonar.offset_down_m
        ox, oy, oz = c.x + off * bzx, c.y + off * bzy, c.z + off * bzz
        dist, surface = self._geom.raycast(ox, oy, oz, bzx, bzy, bzz)
        if dist > self.world.sensors.sonar.max_m:
            return None, FloorMaterial.HARD
        material = FloorMaterial.HARD
        if surface == FLOOR:
            material = self.world.floor_material(ox + dist * bzx, oy + dist * bzy)
        return dist, material

    def sonar(self) -> SonarSample | None:
        """A sonar reading that arrived since the last call (the newest), else None."""
        return self._sonar.poll(self.t_s)

    @property
    def sonar_stats(self) -> tuple[int, int]:
        """(late echoes, dropouts) so far, both from carpet."""
        return self._sonar.late_echoes, self._sonar.dropouts

    def baro(self) -> BaroSample:
        """MS5611 reading now; alt_m is relative to where the vehicle booted."""
        c = self._core
        rest_z = self._geom.support_z(c.x, c.y, c.z) - self.params.gear_height_m
        d = derived(self.params)
        thrust = d.k_thrust * (c.m0**2 + c.m1**2 + c.m2**2 + c.m3**2)
        thrust_frac = thrust / (4.0 * self.params.max_thrust_per_motor_n)
        return self._baro.sample(self.t_s, self._baro_z0 - c.z, rest_z - c.z, thrust_frac)

    def proximity(self, others_n: Sequence[Vec3] = ()) -> list[ProximitySample]:
        """Six IR readings: front, right, back, left, up, down.

        `others_n` are the positions of other vehicles in the same world (flocking): each is
        seen as a box the size of this airframe's body, named "vehicle".
        """
        c = self._core
        r, h = self.params.body_radius_m, self.params.body_half_height_m
        extra = tuple(
            (x - r, y - r, z - h, x + r, y + r, z + h, OTHER_VEHICLE) for x, y, z in others_n
        )
        return self._prox.sample(self._geom, (c.x, c.y, c.z), (c.qw, c.qx, c.qy, c.qz), extra)

    def radiation(self, dt_s: float) -> float | None:
        """Counts/s over a window of dt_s ending now; None when the world has no sources."""
        if not self.world.sources:
            return None
        c = self._core
        return self._rad.sample((c.x, c.y, c.z), dt_s)

    def mocap(self) -> MocapSample | None:
        """The oldest motion-capture pose delivered by now, else None (call until None)."""
        if self._mocap is None:
            return None
        return self._mocap.poll(self.t_s)
