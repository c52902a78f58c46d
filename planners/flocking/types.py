"""The triangular flock's vocabulary: moves, modes, phases, the mission, one step's output."""

from __future__ import annotations

import enum
import math
from collections import deque
from dataclasses import dataclass, field

from planners.flocking.formation import Role
from planners.geometry import Vec3
from planners.proximity import ProximityReading

# The six grid moves: north, south, east, west, down, up (NED unit vectors).
AXIS_MOVES: tuple[Vec3, ...] = (
    (1.0, 0.0, 0.0),
    (-1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (0.0, -1.0, 0.0),
    (0.0, 0.0, 1.0),
    (0.0, 0.0, -1.0),
)


class VehicleMode(enum.Enum):
    """What a vehicle did this step."""

    FORMATION = "formation"  # flying to its goal (leader: to the common goal)
    WAITING = "waiting"  # at its goal with nothing new from its leader, or held by the guard
    AVOIDING = "avoiding"  # manoeuvring round an obstacle on its own sensors
    TRAIL = "trail"  # walking its leader's trail (heads-up), in its own altitude layer
    INDIVIDUAL = "individual"  # flying to its individual goal
    ARRIVED = "arrived"  # at its individual goal


class Phase(enum.Enum):
    """Common goal first, then individual goals (Algorithms 9.3.3 and 9.3.4)."""

    COMMON_GOAL = "common_goal"
    INDIVIDUAL_GOALS = "individual_goals"


@dataclass(frozen=True, slots=True)
class FlockMission:
    """Where the team goes: the common goal of the root, then optional individual goals by id."""

    common_goal_n: Vec3
    individual_goals_n: dict[int, Vec3] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class FlockStep:
    """Output of one planning step: set positions by vehicle id, and diagnostics."""

    setpoints_n: dict[int, Vec3]
    messages_sent: int  # leader positions sent to followers (eq. 9.1)
    modes: dict[int, VehicleMode]
    roles: dict[int, Role]
    phase: Phase
    formation_error_m: float | None  # RMS slot error of followers flying in formation
    formation_samples: tuple[float, ...]
    leader_avoiding: bool
    held_by_guard: tuple[int, ...]
    # Ordered (reader, owner) pairs of vehicles where the reader used the owner's state this
    # step: the guard's positions and planned set points, make-way requests, a leader's queueing
    # flag, the team's settled flags. Each pair is one message, the unit the all-to-all
    # baseline is billed in (N·(N−1) per step); eq. 9.1's positions are counted apart.
    state_reads: int = 0

    @property
    def messages_total(self) -> int:
        """Every message of the step: eq. 9.1's positions plus the state reads."""
        return self.messages_sent + self.state_reads


@dataclass(slots=True)
class VehicleState:
    """Runtime state of one vehicle (tree index), shared by the planner, its moves and the guard."""

    goal_n: Vec3 | None = None
    trail: deque[Vec3] = field(default_factory=deque)
    trail_idx: int = 0
    in_trail: bool = False
    trail_layer_on: bool = True
    clear_steps: int = 0
    hits: deque[Vec3] = field(default_factory=deque)
    avoid_dir: Vec3 | None = None
    overshoot: int = 0
    arrived_common: bool = False
    individual: bool = False  # flying its individual goal (Algorithm 9.3.4)
    arrived_final: bool = False
    make_way_from: list[Vec3] = field(default_factory=list)  # where higher-priority ones wanted
    keep_clear: list[tuple[Vec3, int]] = field(default_factory=list)  # (point, until step)
    guard_blocked: int = 0  # consecutive steps the guard refused this vehicle's best move
    overfly: bool = False  # climbing over teammates that block the way to its goal


def step_along(p: Vec3, d: Vec3, s: float) -> Vec3:
    """``p`` moved ``s`` metres along the unit vector ``d``."""
    return (p[0] + d[0] * s, p[1] + d[1] * s, p[2] + d[2] * s)


def dist(a: Vec3, b: Vec3) -> float:
    """Euclidean distance in metres."""
    return math.dist(a, b)


def sensor_free(reading: ProximityReading, d: Vec3, s: float, stop_distance_m: float) -> bool:
    """A move of ``s`` along ``d`` stops ``stop_distance_m`` short of what the sensor there sees."""
    r = reading.along_n(d)
    return r is None or r > s + stop_distance_m
