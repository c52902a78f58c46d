"""Altitude estimation from the IMU and the sonar: a dead-reckoning baseline (thesis eq. 6.1),
a third-order complementary filter (as APM's inertial navigation) and a Kalman filter that also
fuses the barometer to bridge the sonar's gaps over carpet."""

from gcs.estimation.base import AltEstimator
from gcs.estimation.complementary import ComplementaryEstimator
from gcs.estimation.dead_reckoning import DeadReckoningEstimator
from gcs.estimation.estimate import AltEstimate, EstimatorCounts, SonarStatus
from gcs.estimation.inputs import (
    GRAVITY_MPS2,
    baro_altitude_m,
    sonar_altitude_m,
    vertical_accel_up_mps2,
)
from gcs.estimation.kalman import KalmanEstimator
from gcs.estimation.params import EstimatorParams

__all__ = [
    "GRAVITY_MPS2",
    "AltEstimate",
    "AltEstimator",
    "ComplementaryEstimator",
    "DeadReckoningEstimator",
    "EstimatorCounts",
    "EstimatorParams",
    "KalmanEstimator",
    "SonarStatus",
    "baro_altitude_m",
    "make_estimator",
    "sonar_altitude_m",
    "vertical_accel_up_mps2",
]


def make_estimator(kind: str, params: EstimatorParams | None = None) -> AltEstimator:
    """Build an estimator by name: "kalman", "complementary" or "dead_reckoning"."""
    p = params or EstimatorParams()
    table: dict[str, type[AltEstimator]] = {
        "kalman": KalmanEstimator,
        "complementary": ComplementaryEstimator,
        "dead_reckoning": DeadReckoningEstimator,
    }
    if kind not in table:
        raise ValueError(f"unknown estimator {kind!r}; expected one of {sorted(table)}")
    return table[kind](p)
