"""EPBHA's vocabulary: moves, planes, statuses, obstacle classes, reasons, parameters, decisions.

The planner itself is :mod:`planners.epbha.planner`; these are the names its decisions are made of.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from planners.geometry import Vec3


class Move(enum.Enum):
    """The six grid moves, as unit vectors in local NED."""

    NORTH = (1, 0, 0)
    SOUTH = (-1, 0, 0)
    EAST = (0, 1, 0)
    WEST = (0, -1, 0)
    DOWN = (0, 0, 1)
    UP = (0, 0, -1)

    @property
    def axis(self) -> int:
        """Index of the NED axis the move is along."""
        return next(i for i, c in enumerate(self.value) if c != 0)

    @property
    def sign(self) -> int:
        """+1 or -1 along the move's axis."""
        return self.value[self.axis]

    @property
    def opposite(self) -> Move:
        """The move back."""
        return _OPPOSITE[self]

    def vec(self) -> Vec3:
        """The unit vector as floats."""
        return (float(self.value[0]), float(self.value[1]), float(self.value[2]))


_OPPOSITE = {
    Move.NORTH: Move.SOUTH,
    Move.SOUTH: Move.NORTH,
    Move.EAST: Move.WEST,
    Move.WEST: Move.EAST,
    Move.DOWN: Move.UP,
    Move.UP: Move.DOWN,
}
AXIS_MOVES = {0: (Move.NORTH, Move.SOUTH), 1: (Move.EAST, Move.WEST), 2: (Move.DOWN, Move.UP)}


class Plane(enum.Enum):
    """The plane searched: first the XY-plane goal, then the YZ-plane goal (Definition 1)."""

    XY = (0, 1, 2)  # (axis weighted A, axis weighted B, out-of-plane axis)
    YZ = (1, 2, 0)


class Status(enum.Enum):
    """What the planner tells the vehicle to do."""

    MOVING = "moving"
    REACHED = "reached"
    DEADLOCK = "deadlock"


class ObstacleClass(enum.Enum):
    """Obstacle types EPBHA tells apart by its active sensors (§8.5, §9.3)."""

    NONE = "none"
    SINGLE_SIDED = "single-sided"
    PARTITION = "partition"
    CAVE = "cave"


class Reason(enum.Enum):
    """Why the planner chose this set position."""

    COST = "minimum cost neighbour"
    KEEP_OFF = "keep off a near obstacle"
    GO_AROUND = "go around a single-sided obstacle"
    PASS_ALONG = "pass alongside the obstacle"
    PASS_OVER = "pass over a partition"
    BACK_OFF = "back off diagonally from a cave"
    REACHED = "goal reached"
    DEADLOCK_BLOCKED = "deadlock: no free move"
    DEADLOCK_LOOP = "deadlock: revisiting the same cells"


@dataclass(frozen=True, slots=True)
class EpbhaParams:
    """EPBHA tuning; thesis values where the thesis gives one (sensors §8.6)."""

    step_m: float = 0.1  # grid step d (the thesis leaves it to calibration)
    weight_a: float = 4.0  # A of Definition 2, on the plane's first axis (x in XY, y in YZ)
    weight_b: float = 2.0  # B of Definition 2, on the plane's second axis
    sensor_range_m: float = 0.5  # §8.6
    sensor_cone_deg: float = 45.0  # §8.6, full cone angle
    keep_off_m: float = 0.25  # Subfunction 2's offset: the 0.15 m body plus 10 cm
    # The same offset above and below (None: keep_off_m, as the thesis has it). A quadrotor is
    # a flat disk: under a table its sensors at mid-body need its half-height plus the height
    # hold's error, not its radius, and a gap too narrow for 2 x keep_off_m would make a hold
    # a centimetre high step down onto whatever lies below.
    keep_off_vertical_m: float | None = None
    body_radius_m: float = 0.17  # edge clearance wanted: the 0.15 m body plus 2 cm
    # A move's path must keep this far from every return remembered: the 0.15 m body plus 2 cm.
    # Not body_radius_m, which a mission may raise for position-hold error around edges seen.
    swept_clearance_m: float = 0.17
    # The same above and below (None: swept_clearance_m). The flat body's vertical need is its
    # half-height plus the height hold's error: a table top 0.2 m over the sensors is clear.
    swept_clearance_vertical_m: float | None = None
    # A move must pass this far from the edge a blind wedge beside it may hide
    # (planners.epbha.wedges): the 0.15 m body plus 1 cm, less margin than for a return
    # remembered, as that edge is placed as near as the readings allow, never farther.
    wedge_clearance_m: float = 0.16
    # Returns are remembered for this many readings (0.3 m of travel): long enough to keep an
    # edge that slipped into a blind wedge, short enough that a cap's rim, never resolved across
    # the plane the vehicle moves in, does not shut passages it has already measured.
    memory_steps: int = 3
    max_visits: int = 4  # visits of one cell after which the planner reports a loop
    max_alt_m: float = 2.0  # §8.1: the approximate maximum altitude indoors; never climb above

    def __post_init__(self) -> None:
        if not self.step_m > 0.0:
            raise ValueError(f"EPBHA step_m must be > 0, got {self.step_m}")
        if not (self.weight_a > 0.0 and self.weight_b > 0.0):
            raise ValueError("EPBHA weights A and B must be > 0")
        if not self.sensor_range_m > 0.0 or self.keep_off_m < 0.0:
            raise ValueError("EPBHA sensor_range_m must be > 0 and keep_off_m >= 0")
        if self.keep_off_vertical_m is not None and self.keep_off_vertical_m < 0.0:
            raise ValueError("EPBHA keep_off_vertical_m must be >= 0")
        for name, k in (("keep_off_m", self.keep_off_m),
                        ("keep_off_vertical_m", self.keep_off_vertical_m or 0.0)):
            if self.step_m + k >= self.sensor_range_m:
                raise ValueError(
                    f"EPBHA step_m + {name} ({self.step_m + k} m) must be below the sensor "
                    f"range ({self.sensor_range_m} m), or a blocked move is never seen"
                )
        if not self.max_alt_m > 0.0:
            raise ValueError(f"EPBHA max_alt_m must be > 0, got {self.max_alt_m}")
        if self.body_radius_m < 0.0 or self.max_visits < 1:
            raise ValueError("EPBHA body_radius_m must be >= 0 and max_visits >= 1")
        for name in ("swept_clearance_m", "wedge_clearance_m"):
            if getattr(self, name) < 0.0:
                raise ValueError(f"EPBHA {name} must be >= 0, got {getattr(self, name)}")
        v = self.swept_clearance_vertical_m
        if v is not None and not v > 0.0:
            raise ValueError(f"EPBHA swept_clearance_vertical_m must be > 0, got {v}")
        if self.memory_steps < 1:
            raise ValueError(f"EPBHA memory_steps must be >= 1, got {self.memory_steps}")

    @property
    def swept_z_scale(self) -> float:
        """How much farther a remembered return above or below counts than one beside."""
        v = self.swept_clearance_vertical_m
        if v is None or self.swept_clearance_m == 0.0:
            return 1.0
        return self.swept_clearance_m / v

    def keep_off(self, move: Move) -> float:
        """Subfunction 2's offset along `move`: the vertical one up and down."""
        if move in (Move.UP, Move.DOWN) and self.keep_off_vertical_m is not None:
            return self.keep_off_vertical_m
        return self.keep_off_m

    def blocked_below(self, move: Move) -> float:
        """A move is blocked when its sensor sees something nearer than this."""
        return self.step_m + self.keep_off(move)


@dataclass(frozen=True, slots=True)
class CostEntry:
    """One row of the cost table: a candidate neighbour and its cost (Definition 2)."""

    move: Move
    pos_n: Vec3
    cost: float
    free: bool


@dataclass(frozen=True, slots=True)
class Decision:
    """One EPBHA step: the next set position and why."""

    next_pos_n: Vec3
    status: Status
    reason: Reason
    obstacle: ObstacleClass
    plane: Plane
    heading: Move | None
    costs: tuple[CostEntry, ...]
    cost_evaluations: int  # entries computed this step (0 during a manoeuvre)
    movement_options: int  # sensors that see nothing (Subfunction 3)
