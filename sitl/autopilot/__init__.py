"""ArduCopter-like autopilot: attitude and altitude control, modes, failsafes, parameters."""

from sitl.autopilot.autopilot import (
    Autopilot,
    AutopilotState,
    CommandResult,
    SensorSample,
    Severity,
    SystemStatus,
)
from sitl.autopilot.params import Key, ParamError, ParamStore, ParamType, param_table
from sitl.autopilot.profile import FlightMode, Profile

__all__ = [
    "Autopilot",
    "AutopilotState",
    "CommandResult",
    "FlightMode",
    "Key",
    "ParamError",
    "ParamStore",
    "ParamType",
    "Profile",
    "SensorSample",
    "Severity",
    "SystemStatus",
    "param_table",
]
