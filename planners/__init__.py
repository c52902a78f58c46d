"""Pure path-planning algorithms of the thesis and their baselines: no I/O, no clocks."""

from planners.astar import astar_search, plan_astar
from planners.dstar_lite import DStarLite, run_dstar_lite
from planners.epbha import Decision, Epbha, EpbhaParams, ObstacleClass, run_epbha
from planners.geometry import Box, Vec3, World
from planners.grid import Grid, GridParams
from planners.kinematic import KinematicParams, KinematicSim, MoveOutcome
from planners.proximity import Facing, ProximityParams, ProximityReading, sense
from planners.result import PlanResult, PlanStatus

__all__ = [
    "Box",
    "DStarLite",
    "Decision",
    "Epbha",
    "EpbhaParams",
    "Facing",
    "Grid",
    "GridParams",
    "KinematicParams",
    "KinematicSim",
    "MoveOutcome",
    "ObstacleClass",
    "PlanResult",
    "PlanStatus",
    "ProximityParams",
    "ProximityReading",
    "Vec3",
    "World",
    "astar_search",
    "plan_astar",
    "run_dstar_lite",
    "run_epbha",
    "sense",
]
