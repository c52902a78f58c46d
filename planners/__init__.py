"""Pure path-planning algorithms of the thesis and their baselines: no I/O, no clocks."""

from planners.geometry import Box, Vec3, World
from planners.kinematic import KinematicParams, KinematicSim, MoveOutcome
from planners.proximity import Facing, ProximityParams, ProximityReading, sense
from planners.result import PlanResult, PlanStatus

__all__ = [
    "Box",
    "Facing",
    "KinematicParams",
    "KinematicSim",
    "MoveOutcome",
    "PlanResult",
    "PlanStatus",
    "ProximityParams",
    "ProximityReading",
    "Vec3",
    "World",
    "sense",
]
