"""Sensor parameters (DESIGN.md realism floor as defaults), overridable per world file.

Every noisy sensor takes an injected numpy Generator; `noise=False` on the vehicle turns every
random imperfection off (noise, bias, vibration, drift, outliers, late echoes) so physics tests
can read exact values. Quantisation and range limits stay on: they are the sensor.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from sitl.params import ParamError, build_dataclass, check_positive, check_range


@dataclass(frozen=True, slots=True)
class ImuParams:
    """MPU-6050: accelerometer and gyro, 16-bit."""

    acc_range_g: float = 2.0  # ±2 g full scale: LSB = 2 g / 32768
    acc_noise_mps2: float = 0.06  # white, RMS per axis
    acc_bias_max_mps2: float = 0.15  # per-run constant bias drawn uniformly in ±this
    acc_vibration_mps2_full: float = 0.8  # vibration RMS at full rotor speed, ∝ mean speed
    # share of that RMS left in the flight controller's own loop-averaged reading (sensors/imu.py):
    # the MPU's 20 Hz DLPF (two poles) against rotor vibration at >= 100 Hz leaves <= 1/25;
    # 1/10 keeps a margin
    vibration_residue: float = 0.1
    gyro_range_dps: float = 2000.0
    gyro_noise_radps: float = 0.006
    gyro_bias_max_radps: float = 0.01
    gyro_vibration_radps_full: float = 0.02
    temperature_c: float = 35.0

    def __post_init__(self) -> None:
        if self.acc_range_g not in (2.0, 4.0, 8.0, 16.0):
            raise ParamError(f"acc_range_g: expected 2, 4, 8 or 16, got {self.acc_range_g!r}")
        if self.gyro_range_dps not in (250.0, 500.0, 1000.0, 2000.0):
            raise ParamError(
                f"gyro_range_dps: expected 250, 500, 1000 or 2000, got {self.gyro_range_dps!r}"
            )
        for name in (
            "acc_noise_mps2",
            "acc_bias_max_mps2",
            "acc_vibration_mps2_full",
            "gyro_noise_radps",
            "gyro_bias_max_radps",
            "gyro_vibration_radps_full",
        ):
            check_range(self, name, 0.0, 100.0)
        check_range(self, "vibration_residue", 0.0, 1.0)


@dataclass(frozen=True, slots=True)
class SonarParams:
    """HC-SR04 looking down along body +z."""

    min_m: float = 0.02
    max_m: float = 4.0
    noise_m: float = 0.01
    outlier_prob: float = 0.01
    rate_hz: float = 20.0
    speed_of_sound_mps: float = 340.0
    timeout_s: float = 0.038  # HC-SR04 ends its echo pulse after ~38 ms when nothing returns
    offset_down_m: float = 0.05  # below the centre of gravity: on the ground it reads < min
    carpet_late_prob: float = 0.3  # share of pings over carpet whose echo comes back late
    carpet_max_delay_s: float = 1.2  # thesis Ch. 7: up to 1.2 s
    carpet_dropout_prob: float = 0.2  # share of pings over carpet that never return

    def __post_init__(self) -> None:
        check_positive(self, "min_m", "max_m", "rate_hz", "speed_of_sound_mps", "timeout_s")
        if self.min_m >= self.max_m:
            raise ParamError(f"min_m: must be below max_m ({self.max_m}), got {self.min_m}")
        for name in ("outlier_prob", "carpet_late_prob", "carpet_dropout_prob"):
            check_range(self, name, 0.0, 1.0)
        check_range(self, "noise_m", 0.0, 10.0)
        check_range(self, "carpet_max_delay_s", 0.0, 10.0)
        check_range(self, "offset_down_m", -1.0, 1.0)


@dataclass(frozen=True, slots=True)
class BaroParams:
    """MS5611 barometer."""

    noise_m: float = 0.12  # white, altitude-equivalent RMS
    drift_amplitude_m: float = 0.3  # slow sinusoidal drift (random phase per run)
    drift_period_s: float = 700.0
    ground_effect_m: float = 0.2  # downwash reads this much low at full thrust on the ground
    ground_effect_height_m: float = 0.3  # fades to nothing at this height above the surface
    temperature_c: float = 25.0
    temperature_noise_c: float = 0.05

    def __post_init__(self) -> None:
        check_positive(self, "drift_period_s", "ground_effect_height_m")
        for name in ("noise_m", "drift_amplitude_m", "ground_effect_m", "temperature_noise_c"):
            check_range(self, name, 0.0, 100.0)


@dataclass(frozen=True, slots=True)
class ProximityParams:
    """Six body-fixed IR rangers (thesis §8.6: 0.5 m, 45° cone)."""

    max_m: float = 0.5
    cone_deg: float = 45.0  # full angle
    noise_m: float = 0.012
    rays_per_ring: int = 8  # rays on the cone edge and on a half-angle ring, plus the axis

    def __post_init__(self) -> None:
        check_positive(self, "max_m")
        check_range(self, "cone_deg", 0.0, 170.0)
        check_range(self, "noise_m", 0.0, 1.0)
        if not 1 <= self.rays_per_ring <= 64:
            raise ParamError(f"rays_per_ring: expected 1..64, got {self.rays_per_ring!r}")


@dataclass(frozen=True, slots=True)
class RadiationParams:
    """Counting detector."""

    softening_m: float = 0.1  # rate = S·(1 + ε²)/(d² + ε²): finite at the source, S at 1 m

    def __post_init__(self) -> None:
        check_positive(self, "softening_m")


@dataclass(frozen=True, slots=True)
class MocapParams:
    """Off-board motion capture."""

    rate_hz: float = 100.0
    latency_s: float = 0.015
    pos_noise_m: float = 0.002
    att_noise_rad: float = 0.003

    def __post_init__(self) -> None:
        check_positive(self, "rate_hz")
        check_range(self, "latency_s", 0.0, 5.0)
        check_range(self, "pos_noise_m", 0.0, 1.0)
        check_range(self, "att_noise_rad", 0.0, 1.0)


@dataclass(frozen=True, slots=True)
class SensorParams:
    """All sensors of one vehicle."""

    imu: ImuParams = field(default_factory=ImuParams)
    sonar: SonarParams = field(default_factory=SonarParams)
    baro: BaroParams = field(default_factory=BaroParams)
    proximity: ProximityParams = field(default_factory=ProximityParams)
    radiation: RadiationParams = field(default_factory=RadiationParams)
    mocap: MocapParams = field(default_factory=MocapParams)

    @classmethod
    def from_toml(cls, data: Mapping[str, Any], where: str = "sensors") -> SensorParams:
        """From a `[sensors.*]` table; unknown sensors or fields are errors."""
        return build_dataclass(cls, data, where)
