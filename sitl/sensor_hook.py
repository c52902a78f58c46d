"""Where a fault can reach a vehicle's sensors: what the runtime reads each tick, passed through
a hook before the autopilot and the telemetry see it.

`VehicleRuntime.sensor_hook` is None in every flight a user flies; a fault search (`lab`) puts
an object with these three methods there, so a sonar dropout, a stuck IMU or a battery sag is a
change of the readings the firmware gets, not of the physics: the vehicle still flies the truth.
"""

from __future__ import annotations

from typing import Protocol

from sitl.battery import BatteryState
from sitl.sensors.imu import ImuSample
from sitl.sensors.sonar import SonarSample


class SensorHook(Protocol):
    """Readings in, readings out, on the vehicle's simulated time."""

    def imu(self, t_s: float, sample: ImuSample) -> ImuSample: ...

    def sonar(self, t_s: float, sample: SonarSample | None) -> SonarSample | None: ...

    def battery(self, t_s: float, state: BatteryState) -> BatteryState: ...
