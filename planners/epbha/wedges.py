"""Box edges that may hide in the blind wedge between the travel cone and a side cone.

Six 45° cones leave a wedge between each two perpendicular ones. A box whose edge lies in the
wedge between the cone ahead (axis u) and a side cone (axis w), at x along u and y along w,
shows each cone only a face, at the cone's rim: the face across w is nearest inside the u-cone
at y / sin(half cone), the face across u nearest inside the w-cone at x / sin(half cone). The
edge itself is seen by neither, and a step along u passes it at y however near it is: flying
on after a turn over a box top 0.15 m below, or up to the top edge of a box ahead.

Read back, the two readings place that edge at (r_w·sin, r_u·sin), exactly for a box whose
faces reach both rims; a nearer surface seen by either cone only brings the placed edge nearer,
and a cone that sees nothing puts it range·sin away. An edge inside a cone (x beyond
y / tan(half cone)) is a return, kept by the memory of returns instead. A box too short to
reach the rims, hiding in the wedge altogether, is not caught here.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from planners.epbha.types import AXIS_MOVES, Move
from planners.proximity import ProximityReading


def wedge_edges(
    reading: ProximityReading, travel: Move, cone_deg: float, range_m: float
) -> Iterator[tuple[Move, float, float]]:
    """For each side across `travel`: that side and the edge's offsets ahead and aside (m)."""
    sin_half = math.sin(math.radians(cone_deg) / 2.0)

    def offset(move: Move) -> float:
        seen = reading.along_n(move.vec())
        return sin_half * (range_m if seen is None or seen > range_m else seen)

    aside = offset(travel)
    for axis, pair in AXIS_MOVES.items():
        if axis != travel.axis:
            for side in pair:
                yield side, offset(side), aside


def wedge_clear(
    reading: ProximityReading,
    travel: Move,
    step_m: float,
    clearance_m: float,
    z_scale: float,
    cone_deg: float,
    range_m: float,
) -> bool:
    """A step along `travel` passes every edge the wedges beside it may hide by `clearance_m`.

    `z_scale` stretches vertical offsets as for remembered returns (a flat body).
    """
    for side, ahead, aside in wedge_edges(reading, travel, cone_deg, range_m):
        su = z_scale if travel.axis == 2 else 1.0
        sw = z_scale if side.axis == 2 else 1.0
        if math.hypot(su * max(0.0, ahead - step_m), sw * aside) < clearance_m - 1e-9:
            return False
    return True
