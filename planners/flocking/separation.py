"""How close the vehicles of a team come to each other on straight moves between steps.

The minimum is exact between the steps (the closest approach of two linear motions), not a
sample at step times.
"""

from __future__ import annotations

import math

import numpy as np

VEHICLE_COLLISION_M = 0.45  # centres closer than the 0.45 m frame diagonal touch


def _closest_approach(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> float:
    """Smallest distance between two points moving linearly from p0→p1 and q0→q1 over [0, 1]."""
    d0 = p0 - q0
    dv = (p1 - p0) - (q1 - q0)
    vv = float(dv @ dv)
    t = 0.0 if vv < 1e-15 else min(1.0, max(0.0, -float(d0 @ dv) / vv))
    return float(np.linalg.norm(d0 + t * dv))


def pairwise_min_m(prev: np.ndarray, new: np.ndarray) -> float:
    """Minimum pairwise distance over one step of linear moves (exact between the steps)."""
    n = len(prev)
    d_end = np.linalg.norm(new[:, None, :] - new[None, :, :], axis=2) + np.eye(n) * 1e9
    best = float(d_end.min()) if n > 1 else math.inf
    # Only pairs that came within reach need the exact in-between check.
    d_start = np.linalg.norm(prev[:, None, :] - prev[None, :, :], axis=2) + np.eye(n) * 1e9
    moved = np.linalg.norm(new - prev, axis=1)
    reach = moved[:, None] + moved[None, :]
    close = np.argwhere(np.minimum(d_start, d_end) - reach < best)
    for i, j in close:
        if i < j:
            best = min(best, _closest_approach(prev[i], new[i], prev[j], new[j]))
    return best
