"""Multi-vehicle runner with a deterministic step API.

`Simulation(world, profile, n_vehicles, seed)` owns N vehicles (system ids 1..N), each with its
physics (`SimVehicle`), autopilot and MAVLink links. `step(dt_s)` / `run_until(t_s)` advance
physics, autopilot and telemetry scheduling on simulated time only; `memory_link(sysid)` gives
an in-memory byte pipe a pymavlink MAVLink object can talk through deterministically. The
socket endpoints (`sitl.link.endpoints`) pump the same channels in real time.

The autopilot runs at 100 Hz (the APM 2.5's main loop); the physics sub-steps at 400 Hz inside
each tick. The barometer feeds the inertial navigation at 10 Hz, as on the APM 2.x.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sitl.autopilot import Autopilot, AutopilotOptions, ParamStore, Profile, SensorSample
from sitl.autopilot.params import Key
from sitl.autopilot.rangefinder import firmware_reading
from sitl.link.channel import Channel
from sitl.link.handler import VehicleLink
from sitl.link.view import GeoOrigin, VehicleView
from sitl.sensor_hook import SensorHook
from sitl.sensors import MocapSample
from sitl.tick_record import tick_record
from sitl.vehicle_model import SimVehicle
from sitl.world import World, WorldError
from worldfile import vehicle_start

LOOP_RATE_HZ = 100.0
BARO_RATE_HZ = 10.0
PROXIMITY_RATE_HZ = 10.0
RADIATION_RATE_HZ = 5.0


@tick_record
class MocapFrame:
    """A motion-capture pose of one vehicle, delivered at `delivered_t_s`."""

    sysid: int
    sample: MocapSample


class VehicleRuntime:
    """One vehicle: physics + autopilot + links, advanced one loop tick at a time."""

    def __init__(
        self,
        sysid: int,
        world: World,
        profile: Profile,
        start_pos_n: Sequence[float],
        rng: np.random.Generator,
        noise: bool,
        signing_key: bytes | None,
        options: AutopilotOptions | None = None,
    ) -> None:
        self.sysid = sysid
        options = options or world.autopilot
        self.vehicle = SimVehicle(world, start_pos_n=start_pos_n, rng=rng, noise=noise)
        self.params = ParamStore(profile, options)
        self.params.set_key(Key.SYSID_THISMAV, sysid)
        o = world.origin
        sonar = world.sensors.sonar
        # the owner set the rangefinder's maximum for the fitted HC-SR04; its minimum stays the
        # firmware's (RNGFND1_MIN 0.2 m, RNGFND_MIN_CM 20): below it the firmware flies blind
        self.params.set_key(Key.RNG_MAX_M, sonar.max_m)
        self.autopilot = Autopilot(profile, self.params, self.vehicle.hover_throttle(), options)
        for name, value in options.params:  # the owner's values win over the set-up above
            try:
                self.params.set(name, value)
            except ValueError as exc:
                raise WorldError(f"autopilot.params.{name}: {exc} in {profile.value}") from None
        self.view = VehicleView(
            sysid=sysid,
            profile=profile,
            autopilot=self.autopilot,
            params=self.params,
            origin=GeoOrigin(o.lat_deg, o.lon_deg, o.alt_amsl_m),
            sonar_min_m=sonar.min_m,
            sonar_max_m=sonar.max_m,
            has_radiation=bool(world.sources),
            signing_key=signing_key if profile.mavlink2 else None,
        )
        self.link = VehicleLink(self.view)
        self._next_baro_s = 0.0
        self._next_prox_s = 0.0
        self._next_rad_s = 0.0
        self.mocap_out: list[MocapFrame] = []
        # faults on the readings (a fault search's, `sitl.sensor_hook`); None in every flight
        self.sensor_hook: SensorHook | None = None
        self._refresh_cache()

    def add_channel(
        self, port: int, name: str, truth_max_rate_hz: float = math.inf
    ) -> Channel:
        """A new link for this vehicle (SR<port>_* rates, ground truth capped)."""
        return self.link.add_channel(port, name, truth_max_rate_hz)

    def tick(self, dt_s: float) -> None:
        """Sensors → autopilot → physics → telemetry, for one loop period."""
        v = self.vehicle
        t = v.t_s
        self.view.t_s = t
        hook = self.sensor_hook
        imu = v.imu() if hook is None else hook.imu(t, v.imu())
        c = self.view.cache
        c.acc_b, c.gyro_b, c.temperature_c = imu.acc_b, imu.gyro_b, imu.temperature_c
        baro_alt = None
        if t + 1e-9 >= self._next_baro_s:
            self._next_baro_s += 1.0 / BARO_RATE_HZ
            b = v.baro()
            baro_alt = b.alt_fw_m  # the firmware's driver's average; the station gets b.alt_m
            c.pressure_pa = b.pressure_pa
        sonar = v.sonar() if hook is None else hook.sonar(t, v.sonar())
        sonar_m = None
        if sonar is not None:
            c.sonar_m = sonar.distance_m if sonar.valid else None
            reading = firmware_reading(self.params, c.sonar_m)
            c.rangefinder = reading
            # the autopilot uses only what its driver calls in range (not below RNGFND min)
            sonar_m = reading.distance_cm / 100.0 if reading.valid else None
        batt = v.battery if hook is None else hook.battery(t, v.battery)
        c.battery_v, c.current_a = batt.voltage_v, batt.current_a
        c.remaining_pct = batt.remaining_pct
        if t + 1e-9 >= self._next_prox_s:
            self._next_prox_s += 1.0 / PROXIMITY_RATE_HZ
            c.proximity_m = tuple(s.distance_m for s in v.proximity())
        if self.view.has_radiation and t + 1e-9 >= self._next_rad_s:
            self._next_rad_s += 1.0 / RADIATION_RATE_HZ
            c.radiation_cps = v.radiation(1.0 / RADIATION_RATE_HZ)
        sample = SensorSample(
            gyro_b=imu.gyro_b,
            acc_b=imu.acc_b,
            baro_alt_m=baro_alt,
            sonar_m=sonar_m,
            sonar_fresh=sonar is not None,
            battery_v=batt.voltage_v,
            acc_fw_b=imu.acc_fw_b,  # the firmware's own loop-averaged reading
        )
        out = self.autopilot.update(sample, t, dt_s)
        v.step(out.physics_order(), dt_s)
        self.view.t_s = v.t_s
        self._refresh_cache()
        while (m := v.mocap()) is not None:
            self.mocap_out.append(MocapFrame(self.sysid, m))
        self.link.tick(v.t_s)

    def _refresh_cache(self) -> None:
        tr = self.vehicle.truth
        c = self.view.cache
        c.truth_pos_n = tr.pos_n
        c.truth_vel_n = tr.vel_n
        c.truth_q_nb = tr.q_nb
        c.truth_euler = (tr.roll_rad, tr.pitch_rad, tr.yaw_rad)
        c.truth_omega_b = tr.omega_b
        w, x, y, z = tr.q_nb
        an = (tr.acc_n[0], tr.acc_n[1], tr.acc_n[2] - 9.80665)
        # specific force in body: R^T (a - g)
        c.truth_acc_b = (
            (1 - 2 * (y * y + z * z)) * an[0]
            + 2 * (x * y + w * z) * an[1]
            + 2 * (x * z - w * y) * an[2],
            2 * (x * y - w * z) * an[0]
            + (1 - 2 * (x * x + z * z)) * an[1]
            + 2 * (y * z + w * x) * an[2],
            2 * (x * z + w * y) * an[0]
            + 2 * (y * z - w * x) * an[1]
            + (1 - 2 * (x * x + y * y)) * an[2],
        )


class MemoryLink:
    """In-memory byte pipe to one vehicle: write what a GCS sends, read what the vehicle sent."""

    def __init__(self, runtime: VehicleRuntime, channel: Channel) -> None:
        self._runtime = runtime
        self.channel = channel

    def write(self, data: bytes) -> None:
        """Deliver bytes from the GCS (handled at once, at the current simulated time)."""
        self._runtime.link.receive(self.channel, data)

    def read(self) -> bytes:
        """Everything the vehicle queued on this link since the last read."""
        return self.channel.take()


class Simulation:
    """N vehicles in one world on one simulated clock."""

    def __init__(
        self,
        world: World,
        profile: Profile = Profile.APM25,
        n_vehicles: int = 1,
        seed: int = 0,
        noise: bool = True,
        signing_key: bytes | None = None,
        options: AutopilotOptions | None = None,
    ) -> None:
        """`options` override the world's `[autopilot]` settings when given."""
        if n_vehicles < 1:
            raise ValueError(f"n_vehicles: expected at least 1, got {n_vehicles}")
        self.world = world
        self.profile = profile
        self.dt_s = 1.0 / LOOP_RATE_HZ
        self._ticks = 0
        rngs = np.random.default_rng(seed).spawn(n_vehicles)
        starts = world.start_positions_n
        self.vehicles: list[VehicleRuntime] = []
        for i in range(n_vehicles):
            start = vehicle_start(starts, i)
            self.vehicles.append(
                VehicleRuntime(
                    i + 1, world, profile, start, rngs[i], noise, signing_key, options
                )
            )

    @property
    def t_s(self) -> float:
        """Simulated time."""
        return self._ticks * self.dt_s

    def vehicle(self, sysid: int) -> VehicleRuntime:
        """The vehicle with system id `sysid`."""
        if not 1 <= sysid <= len(self.vehicles):
            raise KeyError(f"no vehicle with system id {sysid}")
        return self.vehicles[sysid - 1]

    def memory_link(self, sysid: int = 1, port: int = 0) -> MemoryLink:
        """A new in-memory link to vehicle `sysid`."""
        rt = self.vehicle(sysid)
        return MemoryLink(rt, rt.add_channel(port, f"memory{len(rt.link.channels)}"))

    def tick(self) -> None:
        """Advance one loop period for every vehicle."""
        for rt in self.vehicles:
            rt.tick(self.dt_s)
        self._ticks += 1

    def step(self, dt_s: float) -> None:
        """Advance by `dt_s` (rounded to whole loop periods)."""
        for _ in range(max(0, math.floor(dt_s / self.dt_s + 1e-6))):
            self.tick()

    def run_until(self, t_s: float) -> None:
        """Advance until simulated time reaches `t_s`."""
        while self.t_s + 1e-9 < t_s:
            self.tick()

    def take_mocap(self) -> list[MocapFrame]:
        """Motion-capture frames delivered since the last call, all vehicles."""
        out: list[MocapFrame] = []
        for rt in self.vehicles:
            out.extend(rt.mocap_out)
            rt.mocap_out.clear()
        return out
