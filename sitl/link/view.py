"""What the MAVLink side reads of one vehicle: filled by the simulation every tick."""

from __future__ import annotations

from dataclasses import dataclass, field

from sitl.autopilot import Autopilot, ParamStore, Profile
from sitl.autopilot.rangefinder import NO_READING, RangeReading


@dataclass
class SensorCache:
    """Latest sensor values and ground truth, SI units, body FRD / local NED."""

    acc_b: tuple[float, float, float] = (0.0, 0.0, -9.80665)
    gyro_b: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pressure_pa: float = 101325.0
    temperature_c: float = 25.0
    sonar_m: float | None = None  # last reading, None = no echo
    rangefinder: RangeReading = NO_READING  # that reading as the firmware's driver holds it
    battery_v: float = 12.6
    current_a: float = 0.0
    remaining_pct: float = 100.0
    proximity_m: tuple[float | None, ...] = (None,) * 6
    radiation_cps: float | None = None
    truth_pos_n: tuple[float, float, float] = (0.0, 0.0, 0.0)
    truth_vel_n: tuple[float, float, float] = (0.0, 0.0, 0.0)
    truth_q_nb: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    truth_euler: tuple[float, float, float] = (0.0, 0.0, 0.0)
    truth_omega_b: tuple[float, float, float] = (0.0, 0.0, 0.0)
    truth_acc_b: tuple[float, float, float] = (0.0, 0.0, -9.80665)


@dataclass(frozen=True)
class GeoOrigin:
    """Where local NED (0, 0, 0) is on the earth, for SIMSTATE/SIM_STATE lat/lon."""

    lat_deg: float = 0.0  # see sitl.world.GeoOrigin for why
    lon_deg: float = 0.0
    alt_amsl_m: float = 60.0


@dataclass
class VehicleView:
    """One vehicle as its links see it."""

    sysid: int
    profile: Profile
    autopilot: Autopilot
    params: ParamStore
    cache: SensorCache = field(default_factory=SensorCache)
    origin: GeoOrigin = field(default_factory=GeoOrigin)
    t_s: float = 0.0
    sonar_min_m: float = 0.02
    sonar_max_m: float = 4.0
    has_radiation: bool = False
    signing_key: bytes | None = None
