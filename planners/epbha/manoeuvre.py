"""The state of one EPBHA manoeuvre around, over or out of an obstacle, and when it is done."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from planners.epbha.types import EpbhaParams, Move, ObstacleClass
from planners.geometry import Vec3
from planners.proximity import ProximityReading


@dataclass(slots=True)
class Manoeuvre:
    """A pre-planned manoeuvre under way: what it avoids, in which directions, how far along."""

    kind: ObstacleClass
    heading: Move  # the blocked direction toward the goal
    side: Move  # lateral side to go around or back off toward
    over: Move  # the bypass direction (up in the XY plane)
    stage: int = 0
    clear_steps: int = 0
    last_seen_m: float = 0.0  # the watched edge's distance when the cone last saw it
    pass_along_m: float = 0.0  # distance still to go alongside before the obstacle is passed
    back_next: bool = True
    lid_z_m: float | None = None  # NED z of a cave's lid underside, when one was measured

    def watch(self, reading: ProximityReading, move: Move, range_m: float) -> int:
        """Steps since the sensor along `move` last saw the edge being cleared."""
        seen = reading.along_n(move.vec())
        if seen is not None and seen <= range_m:
            self.last_seen_m = seen
            return 0
        return self.clear_steps + 1

    def margin_steps(self, params: EpbhaParams) -> int:
        """Extra steps after the edge left the cone until the body has cleared it.

        A 22.5° half-cone stops seeing an edge at lateral offset seen·tan 22.5°, before the
        body has cleared it.
        """
        half = math.radians(params.sensor_cone_deg) / 2.0
        short_m = params.body_radius_m - self.last_seen_m * math.tan(half)
        return max(0, math.ceil(short_m / params.step_m - 1e-9))


def keep_off_move(
    params: EpbhaParams, pos: Vec3, reading: ProximityReading, clear: Callable[[Move], bool]
) -> Move | None:
    """The move away from anything nearer than keep_off, when that evens the gap.

    In a gap narrower than twice keep_off (the goal under a table), backing off one side
    would only bring the other side near: the move is taken only when the far side stays
    farther than the near side after it, so keep-off never oscillates. `clear` says whether
    the swept body of a move clears what has been seen.
    """
    nearest: tuple[float, Move] | None = None
    for move in Move:
        seen = reading.along_n(move.vec())
        if seen is not None and seen < params.keep_off(move) - 1e-9 and (
            nearest is None or seen < nearest[0]
        ):
            nearest = (seen, move)
    if nearest is None:
        return None
    away = nearest[1].opposite
    if away is Move.UP and -pos[2] + params.step_m > params.max_alt_m + 1e-9:
        return None
    far = reading.along_n(away.vec())
    if (far is None or far > nearest[0] + 2.0 * params.step_m + 1e-9) and clear(away):
        return away
    return None
