"""Simulated sensors: IMU, sonar, barometer, IR proximity, radiation, motion capture."""

from sitl.sensor_params import (
    BaroParams,
    ImuParams,
    MocapParams,
    ProximityParams,
    RadiationParams,
    SensorParams,
    SonarParams,
)
from sitl.sensors.baro import BaroModel, BaroSample
from sitl.sensors.imu import ImuModel, ImuSample
from sitl.sensors.mocap import MocapModel, MocapSample
from sitl.sensors.proximity import ProximityFacing, ProximityModel, ProximitySample
from sitl.sensors.radiation import RadiationModel
from sitl.sensors.sonar import SonarModel, SonarSample

__all__ = [
    "BaroModel",
    "BaroParams",
    "BaroSample",
    "ImuModel",
    "ImuParams",
    "ImuSample",
    "MocapModel",
    "MocapParams",
    "MocapSample",
    "ProximityFacing",
    "ProximityModel",
    "ProximityParams",
    "ProximitySample",
    "RadiationModel",
    "RadiationParams",
    "SensorParams",
    "SonarModel",
    "SonarParams",
    "SonarSample",
]
