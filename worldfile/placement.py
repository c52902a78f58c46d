"""Where each vehicle of a flight starts, for the simulator and the station's kinematic runs."""

from __future__ import annotations

from collections.abc import Sequence

from worldfile.schema import Vec3

EXTRA_SPACING_M = 1.0
"""More vehicles than start points: a row this far apart to the east of the last point."""


def vehicle_start(starts: Sequence[Vec3], index: int) -> Vec3:
    """The start of vehicle `index` (0-based): the world's start point of that rank, else a
    place in a row east of the last start point."""
    if index < 0:
        raise ValueError(f"vehicle index: expected >= 0, got {index}")
    if index < len(starts):
        return starts[index]
    base = starts[-1]
    return (base[0], base[1] + EXTRA_SPACING_M * float(index - len(starts) + 1), base[2])
