"""What a grid search baseline (A*, D* Lite) returns: how its search ended, the path flown."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from planners.geometry import Vec3


class SearchStatus(enum.Enum):
    """How a grid search ended."""

    REACHED = "reached"
    GOAL_UNREACHABLE = "goal unreachable"  # a complete search proved no path exists
    MAX_STEPS = "max steps"  # the step budget ran out before the goal
    START_BLOCKED = "start blocked"  # the start (or goal) is inside an obstacle's clearance


@dataclass(frozen=True, slots=True)
class SearchResult:
    """A search baseline's run: status, the path flown (never invented), effort and safety numbers.

    `path` holds the positions visited, start first; when the goal was not reached it ends
    where the vehicle stopped. `cost_evaluations` counts every cost computed for a candidate
    coordinate (an edge relaxation, the unit EPBHA's cost table entries are counted in too);
    `node_expansions` counts nodes popped and expanded.
    """

    planner: str
    status: SearchStatus
    path: tuple[Vec3, ...]
    cost_evaluations: int
    node_expansions: int
    cpu_s_per_step: tuple[float, ...]
    min_clearance_m: float
    collisions: int  # moves that came within the body radius of an obstacle or wall
    detail: str = ""
    penetrations: int = 0  # moves whose segment went through an obstacle or out of the room

    @property
    def reached(self) -> bool:
        """True when the goal was reached."""
        return self.status is SearchStatus.REACHED

    @property
    def path_length_m(self) -> float:
        """Length of the polyline through `path` (m)."""
        return sum(math.dist(a, b) for a, b in zip(self.path, self.path[1:], strict=False))

    @property
    def steps(self) -> int:
        """Moves made (segments in `path`)."""
        return max(0, len(self.path) - 1)

    @property
    def cpu_total_s(self) -> float:
        """CPU time of all planning steps (s)."""
        return sum(self.cpu_s_per_step)

    @property
    def cpu_mean_s_per_step(self) -> float:
        """Mean CPU time per planning step (s)."""
        return self.cpu_total_s / len(self.cpu_s_per_step) if self.cpu_s_per_step else 0.0
