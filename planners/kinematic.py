"""The thesis's kinematic world (§8.6): moves are exact, then the vehicle senses.

The thesis assumes the vehicle reaches every set position without control or dead-reckoning
error. `KinematicSim` does that and keeps the safety books: a move is a collision when its
segment passes through an obstacle or wall, or within the body radius of one. The body radius
defaults to 0.15 m: half the 0.45 m motor diagonal is 0.225 m, but the IR sensors the planner
relies on see only 0.5 m, and a 0.15 m sphere is the airframe's hub and arms inboard of the
props; props overlapping an edge by a few centimetres are tolerated, an arm is not.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from planners.geometry import Vec3, World
from planners.proximity import ProximityParams, ProximityReading, sense

_EPS_M = 1e-9  # passing exactly at the body radius is not a collision, whatever the rounding


@dataclass(frozen=True, slots=True)
class KinematicParams:
    """Vehicle size for collision accounting."""

    body_radius_m: float = 0.15

    def __post_init__(self) -> None:
        if not self.body_radius_m >= 0.0:
            raise ValueError(f"body_radius_m must be >= 0, got {self.body_radius_m}")


@dataclass(frozen=True, slots=True)
class MoveOutcome:
    """What one exact move did: where it ended, its clearance, and whether it collided."""

    pos_n: Vec3
    clearance_m: float
    collided: bool
    penetrated: bool  # the segment passed through an obstacle or left the room


@dataclass(slots=True)
class KinematicSim:
    """Exact-move world: `move_to` relocates the vehicle, `sense` reads the six IR sensors."""

    world: World
    pos_n: Vec3
    params: KinematicParams = field(default_factory=KinematicParams)
    proximity: ProximityParams = field(default_factory=ProximityParams)
    rng: np.random.Generator | None = None
    yaw_rad: float = 0.0
    collisions: int = 0
    penetrations: int = 0
    min_clearance_m: float = math.inf
    path: list[Vec3] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.pos_n = (float(self.pos_n[0]), float(self.pos_n[1]), float(self.pos_n[2]))
        self.path = [self.pos_n]
        self.min_clearance_m = self.world.clearance(self.pos_n)

    def sense(self) -> ProximityReading:
        """Read the six sensors at the current position."""
        return sense(self.world, self.pos_n, self.yaw_rad, self.proximity, self.rng)

    def move_to(self, target_n: Vec3) -> MoveOutcome:
        """Move exactly to `target_n`, counting a collision if the swept body touched anything."""
        target = (float(target_n[0]), float(target_n[1]), float(target_n[2]))
        if target == self.pos_n:
            c = self.world.clearance(target)
            return MoveOutcome(target, c, c < self.params.body_radius_m - _EPS_M, c == 0.0)
        clearance = self.world.segment_clearance(self.pos_n, target)
        penetrated = (
            self.world.segment_hits_obstacle(self.pos_n, target) is not None
            or not self.world.in_room(target)
        )
        collided = penetrated or clearance < self.params.body_radius_m - _EPS_M
        self.collisions += int(collided)
        self.penetrations += int(penetrated)
        self.min_clearance_m = min(self.min_clearance_m, clearance)
        self.pos_n = target
        self.path.append(target)
        return MoveOutcome(target, clearance, collided, penetrated)
