"""The estimate an altitude estimator gives each step, and what it set aside over a flight."""

from __future__ import annotations

import enum
from dataclasses import dataclass


class SonarStatus(enum.Enum):
    """What happened to the sonar on this step."""

    NONE = "none"  # no new reading
    USED = "used"
    GROUND = "ground"  # zero reading near the floor, used as altitude 0
    INVALID = "invalid"  # out of range / zero in the air
    # below the sensor's minimum range with the vehicle known to be off the floor (its take-off
    # saw it lift): the sensor is blind there; the estimate coasts on the accelerometer
    BLIND = "blind"
    DUPLICATE = "duplicate"  # the stream repeating a reading the sensor has not replaced
    REJECTED = "rejected"  # failed the innovation gate (outlier, late echo)
    # consistent readings after rejections (estimate reset to them), or one reading that moved
    # the estimate by a surface step (accepted through a gate widened by a long coast)
    REACQUIRED = "reacquired"
    # the first in-range reading after the blind band, taken through a gate as wide as the
    # band (the coast through it drifted): a correction, not another surface
    UNBLINDED = "unblinded"


@dataclass(frozen=True, slots=True)
class EstimatorCounts:
    """What the estimator set aside over a flight, so that a summary can say so."""

    sonar_rejected: int  # readings that failed the innovation gate
    late_bursts: int  # telemetry bursts integrated again at their samples' own times
    imu_repeats: int  # IMU samples the link delivered twice (integrated once)
    implausible_times: int  # samples stamped ahead of the station's clock (not learned from)


@dataclass(frozen=True, slots=True)
class AltEstimate:
    """Altitude estimate (up positive) and its diagnostics."""

    t_s: float
    alt_m: float
    vel_mps: float
    acc_mps2: float  # bias-corrected upward acceleration used this step
    bias_mps2: float  # estimated accelerometer bias (vertical)
    sonar_used: bool
    sonar_status: SonarStatus
    innovation_m: float  # sonar altitude minus predicted altitude (0 when none)
    sonar_age_s: float  # time since the last accepted sonar reading (inf before any)
    coasting: bool  # no accepted sonar for longer than stale_after_s
    alt_sigma_m: float  # the filter's own standard deviation, nan when it has none
    rejected_total: int
    # what the altitude hold flies on (gcs/estimation/control.py); None: alt_m and vel_mps
    control_alt_m: float | None = None
    control_vel_mps: float | None = None
