"""Pure path-planning algorithms of the thesis and their baselines: no I/O, no clocks."""

from planners.astar import astar_search, plan_astar
from planners.dstar_lite import DStarLite, run_dstar_lite
from planners.epbha import Decision, Epbha, EpbhaParams, ObstacleClass
from planners.epbha_run import run_epbha
from planners.flock_scenes import FlockScene
from planners.flock_sim import FlockPlannerKind, FlockResult, run_flock
from planners.flocking import FlockMission, FlockParams, FlockPlanner, FlockStep
from planners.formation import Formation, FormationParams, Role
from planners.geometry import Box, Vec3, World
from planners.grid import Grid, GridParams
from planners.kinematic import KinematicParams, KinematicSim, MoveOutcome
from planners.lawnmower import run_lawnmower
from planners.proximity import Facing, ProximityParams, ProximityReading, sense
from planners.radiation import Decision as RadiationDecision
from planners.radiation import Phase as RadiationPhase
from planners.radiation import (
    RadiationMapper,
    RadiationMapperParams,
    RadiationResult,
    run_radiation,
)
from planners.radiation import Status as RadiationStatus
from planners.radiation_field import RadiationField
from planners.result import PlanResult, PlanStatus

__all__ = [
    "Box",
    "DStarLite",
    "Decision",
    "Epbha",
    "EpbhaParams",
    "Facing",
    "FlockMission",
    "FlockParams",
    "FlockPlanner",
    "FlockPlannerKind",
    "FlockResult",
    "FlockScene",
    "FlockStep",
    "Formation",
    "FormationParams",
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
    "RadiationDecision",
    "RadiationField",
    "RadiationMapper",
    "RadiationMapperParams",
    "RadiationPhase",
    "RadiationResult",
    "RadiationStatus",
    "Role",
    "Vec3",
    "World",
    "astar_search",
    "plan_astar",
    "run_dstar_lite",
    "run_epbha",
    "run_flock",
    "run_lawnmower",
    "run_radiation",
    "sense",
]
