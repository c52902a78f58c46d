"""Collisions against the SITL's ground truth: the vehicle's body against the world's boxes.

Evaluation only: the truth never feeds the planner or the controllers. The body is the SITL
airframe's contact shape, a flat cylinder (arm tip plus propeller radius 0.25 m, half height
0.04 m); a collision is a contact that begins (one count per contact, not per sample).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from planners.geometry import Box, Vec3

BODY_RADIUS_M = 0.25
BODY_HALF_HEIGHT_M = 0.04


@dataclass(frozen=True, slots=True)
class ContactBooks:
    """What the truth track says about contacts with the world's boxes."""

    collisions: int
    min_clearance_m: float
    touched: tuple[str, ...]
    samples: int


def body_clearance_m(p: Vec3, box: Box, radius_m: float = BODY_RADIUS_M,
                     half_height_m: float = BODY_HALF_HEIGHT_M) -> float:
    """Gap between the cylinder body at `p` and `box` (<= 0: touching)."""
    dx = max(box.min_n[0] - p[0], 0.0, p[0] - box.max_n[0])
    dy = max(box.min_n[1] - p[1], 0.0, p[1] - box.max_n[1])
    dz = max(box.min_n[2] - p[2], 0.0, p[2] - box.max_n[2])
    horizontal = math.hypot(dx, dy) - radius_m
    vertical = dz - half_height_m
    if horizontal > 0.0 and vertical > 0.0:
        return math.hypot(horizontal, vertical)
    return max(horizontal, vertical)


def check_contacts(track_n: Iterable[Vec3], boxes: Sequence[Box]) -> ContactBooks:
    """Count contacts that begin along a truth track (positions in the world's NED frame)."""
    collisions = 0
    touching: set[str] = set()
    touched: list[str] = []
    worst = math.inf
    n = 0
    for p in track_n:
        n += 1
        now: set[str] = set()
        for b in boxes:
            c = body_clearance_m(p, b)
            worst = min(worst, c)
            if c <= 0.0:
                now.add(b.name)
        for name in now - touching:
            collisions += 1
            if name not in touched:
                touched.append(name)
        touching = now
    return ContactBooks(collisions, worst, tuple(touched), n)
