"""ArduCopter-like autopilot: attitude and altitude control, modes, failsafes, parameters."""

from sitl.autopilot.arming import CommandResult, MavResult, Severity
from sitl.autopilot.autopilot import Autopilot
from sitl.autopilot.params import Key, ParamError, ParamStore, ParamType, param_table
from sitl.autopilot.profile import AutopilotOptions, FlightMode, Profile
from sitl.autopilot.state import AutopilotState, SensorSample, SystemStatus

__all__ = [
    "Autopilot",
    "AutopilotOptions",
    "AutopilotState",
    "CommandResult",
    "FlightMode",
    "Key",
    "MavResult",
    "ParamError",
    "ParamStore",
    "ParamType",
    "Profile",
    "SensorSample",
    "Severity",
    "SystemStatus",
    "param_table",
]
