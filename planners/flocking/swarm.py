"""The swarm planners a flock mission can fly, the triangular flock or the Reynolds baseline,
and how each is built for a scene."""

from __future__ import annotations

import enum
from collections.abc import Callable
from typing import Protocol

from planners.flocking.planner import FlockMission, FlockParams, FlockPlanner
from planners.flocking.scenes import FlockScene
from planners.flocking.types import FlockStep
from planners.geometry import Vec3
from planners.proximity import ProximityReading


class SwarmPlanner(Protocol):
    """A planner the flock's mission loop can fly: the triangular flock or the Reynolds
    baseline."""

    name: str

    def step(
        self,
        step_index: int,
        positions_n: dict[int, Vec3],
        readings: dict[int, ProximityReading],
    ) -> FlockStep: ...

    def final_targets_n(self) -> dict[int, Vec3]: ...

    def start_positions_n(self, leader_start_n: Vec3) -> dict[int, Vec3]: ...

    def arrived(self) -> dict[int, bool]: ...


PlannerFactory = Callable[[FlockScene, list[int]], SwarmPlanner]


class FlockPlannerKind(enum.Enum):
    """The two planners of the benchmark."""

    TRIANGULAR = "triangular"
    REYNOLDS = "reynolds"


def scene_mission(scene: FlockScene, vehicle_ids: list[int]) -> FlockMission:
    """The scene's goals for a team whose tree index k is ``vehicle_ids[k]``."""
    goals = {
        vehicle_ids[k]: g for k, g in scene.individual_goals_n.items() if k < len(vehicle_ids)
    }
    return FlockMission(common_goal_n=scene.common_goal_n, individual_goals_n=goals)


def triangular_factory(params: FlockParams | None = None) -> PlannerFactory:
    """Build the triangular flock for a scene."""

    def build(scene: FlockScene, ids: list[int]) -> SwarmPlanner:
        return FlockPlanner(ids, scene_mission(scene, ids), scene.heading_n, params)

    return build


def reynolds_factory() -> PlannerFactory:
    """Build the Reynolds baseline for a scene (same final targets as the flock)."""
    from planners.flocking.reynolds import ReynoldsPlanner

    def build(scene: FlockScene, ids: list[int]) -> SwarmPlanner:
        return ReynoldsPlanner.for_mission(ids, scene_mission(scene, ids), scene.heading_n)

    return build


def factory_for(kind: FlockPlannerKind) -> PlannerFactory:
    """Default factory of a planner kind."""
    return triangular_factory() if kind is FlockPlannerKind.TRIANGULAR else reynolds_factory()
