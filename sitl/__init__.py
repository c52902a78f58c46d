"""The bundled simulated vehicle: physics, ArduCopter-like autopilot, sensors, MAVLink endpoints."""

# ruff: noqa: E402  (before any submodule: the compiled SITL is used only while it matches
# its sources, see sitl/native.py)
from sitl import native as _native

_native.guard()

from sitl.autopilot import AutopilotOptions, FlightMode, Profile
from sitl.battery import BatteryState
from sitl.params import ParamError, VehicleParams
from sitl.physics_state import PhysicsState
from sitl.sensor_params import SensorParams
from sitl.sensors import (
    BaroSample,
    ImuSample,
    MocapSample,
    ProximityFacing,
    ProximitySample,
    SonarSample,
)
from sitl.simulation import MemoryLink, Simulation, VehicleRuntime
from sitl.vehicle_model import SimVehicle, TruthState
from sitl.world import (
    Box,
    FloorMaterial,
    FloorPatch,
    RadiationSource,
    World,
    WorldError,
    default_world,
    load_world,
)

__all__ = [
    "AutopilotOptions",
    "BaroSample",
    "BatteryState",
    "Box",
    "FlightMode",
    "FloorMaterial",
    "FloorPatch",
    "ImuSample",
    "MemoryLink",
    "MocapSample",
    "ParamError",
    "PhysicsState",
    "Profile",
    "ProximityFacing",
    "ProximitySample",
    "RadiationSource",
    "SensorParams",
    "SimVehicle",
    "Simulation",
    "SonarSample",
    "TruthState",
    "VehicleParams",
    "VehicleRuntime",
    "World",
    "WorldError",
    "default_world",
    "load_world",
]
