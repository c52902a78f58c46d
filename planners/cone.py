"""The nearest surface inside a sensing cone, found exactly: boxes and the room's walls.

A ranger that reports the nearest echo in its field of view reports min |x| over the obstacle
points x inside its cone. Sampling the cone with a few rays over-reads that distance or misses
an edge altogether when the edge pokes into the cone between two rays: a box corner 0.14 m
beside the track, just below the sensor plane, lies inside the front cone for several readings
yet no ray of a 17-ray cone touches it.

For a box the minimum is exact and cheap. The nearest point x* of a convex box ∩ cone lies in
the relative interior of one face, edge or vertex of the box; on that face's plane or edge's
line x* is either the foot of the perpendicular from the apex (the cone not binding) or where
the cone binds: on a plane, the point the cone ray nearest the plane's normal hits; on a line,
where the line crosses the cone's surface. Every such candidate is enumerated, those outside
the box or the cone are dropped, and the nearest one is the reading. No line of sight is needed:
the cone is convex about its apex, so anything hiding x* would itself lie nearer inside it.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from planners.geometry import Box, Vec3

_TOL_M = 1e-9
# Vertex selectors (True: the max corner on that axis).
_CORNERS = np.array(list(itertools.product((0, 1), repeat=3)), dtype=bool)
# The 12 edges: the axis each runs along, and the corner at its min end.
_EDGE_AXIS = np.repeat(np.arange(3), 4)
_EDGE_START = np.array(
    [_CORNERS[i] for k in range(3) for i in range(8) if not _CORNERS[i][k]], dtype=bool
)
# The 6 faces: the axis each is across, and whether it is the max face.
_FACE_AXIS = np.repeat(np.arange(3), 2)
_FACE_MAX = np.tile([False, True], 3)
_EDGES = np.arange(12)
_FACES = np.arange(6)


def plane_in_cone_m(distance_m: float, cos_beta: float, half_rad: float) -> float | None:
    """Nearest point inside a cone of a plane `distance_m` ahead of its apex, or None.

    `cos_beta` is the cosine of the angle between the cone's axis and the plane's normal (the
    normal pointing away from the apex); the cone ray nearest that normal reaches the plane at
    distance / cos(max(beta - half, 0)), or never when it runs parallel or away.
    """
    beta = math.acos(max(-1.0, min(1.0, cos_beta)))
    off = max(beta - half_rad, 0.0)
    if off >= math.pi / 2.0 - 1e-12:
        return None
    return distance_m / math.cos(off)


def room_in_cone_m(room: Box, apex: Vec3, axis: Vec3, half_rad: float) -> float | None:
    """From inside `room`, the nearest point of its walls, floor or ceiling inside the cone."""
    best: float | None = None
    for k in range(3):
        for sign, wall in ((1.0, room.max_n[k]), (-1.0, room.min_n[k])):
            d = plane_in_cone_m(max(0.0, sign * (wall - apex[k])), sign * axis[k], half_rad)
            if d is not None and (best is None or d < best):
                best = d
    return best


def boxes_in_cone_m(
    lo: np.ndarray, hi: np.ndarray, axis: Vec3, half_rad: float
) -> float | None:
    """Nearest point of any box [lo_i, hi_i] (rows, apex at the origin) inside the cone, or None.

    0.0 when the apex is inside (or on) a box.
    """
    if lo.shape[0] == 0:
        return None
    if np.any(np.all((lo <= _TOL_M) & (hi >= -_TOL_M), axis=1)):
        return 0.0
    a = np.asarray(axis, dtype=float)
    c, s = math.cos(half_rad), math.sin(half_rad)
    near = np.clip(0.0, lo, hi)
    pts = np.concatenate(
        (
            np.where(_CORNERS[None, :, :], hi[:, None, :], lo[:, None, :]),
            _edge_candidates(lo, hi, near, a, c),
            _face_candidates(lo, hi, near, a, c, s),
        ),
        axis=1,
    )  # (N, M, 3), NaN where a candidate does not exist
    length = np.linalg.norm(pts, axis=2)
    inside = (
        np.all((pts >= lo[:, None, :] - _TOL_M) & (pts <= hi[:, None, :] + _TOL_M), axis=2)
        & (pts @ a >= c * length - _TOL_M)
        & np.isfinite(length)
    )
    if not inside.any():
        return None
    return float(length[inside].min())


def _edge_candidates(
    lo: np.ndarray, hi: np.ndarray, near: np.ndarray, a: np.ndarray, c: float
) -> np.ndarray:
    """On each edge p0 + t e_k (0 <= t <= its length): the foot and the cone-surface crossings."""
    p0 = np.where(_EDGE_START[None, :, :], hi[:, None, :], lo[:, None, :])  # (N, 12, 3)
    length = (hi - lo)[:, _EDGE_AXIS]
    feet = p0.copy()
    feet[:, _EDGES, _EDGE_AXIS] = near[:, _EDGE_AXIS]
    # (a . x)^2 = c^2 |x|^2 along the line: A t^2 + B t + C = 0
    ak = a[_EDGE_AXIS]
    pk = p0[:, _EDGES, _EDGE_AXIS]
    ap = p0 @ a
    qa = np.broadcast_to(ak * ak - c * c, ap.shape)
    qb = 2.0 * (ap * ak - c * c * pk)
    qc = ap * ap - c * c * np.einsum("nej,nej->ne", p0, p0)
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = np.abs(qa) < 1e-12
        disc = np.where(linear, 0.0, qb * qb - 4.0 * qa * qc)
        root = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        t1 = np.where(linear, -qc / qb, (-qb - root) / (2.0 * qa))
        t2 = np.where(linear, np.nan, (-qb + root) / (2.0 * qa))
    out = [feet]
    for t in (t1, t2):
        t = np.where((t >= -_TOL_M) & (t <= length + _TOL_M), t, np.nan)
        crossing = p0.copy()
        crossing[:, _EDGES, _EDGE_AXIS] = pk + t
        out.append(crossing)
    return np.concatenate(out, axis=1)


def _face_candidates(
    lo: np.ndarray, hi: np.ndarray, near: np.ndarray, a: np.ndarray, c: float, s: float
) -> np.ndarray:
    """On each face's plane x_k = d: the foot and the nearest point inside the cone.

    The caller drops the candidates that fall outside their face.
    """
    plane = np.where(_FACE_MAX[None, :], hi[:, _FACE_AXIS], lo[:, _FACE_AXIS])  # (N, 6)
    feet = np.repeat(near[:, None, :], 6, axis=1)
    feet[:, _FACES, _FACE_AXIS] = plane
    # The cone ray nearest the normal n = sign(d) e_k: c a + s (n - (a.n) a) / |n - (a.n) a|.
    sign = np.sign(plane)
    cos_beta = sign * a[_FACE_AXIS]
    sin_beta = np.sqrt(np.clip(1.0 - cos_beta * cos_beta, 0.0, None))
    normal = np.zeros((*plane.shape, 3))
    normal[:, _FACES, _FACE_AXIS] = sign
    with np.errstate(divide="ignore", invalid="ignore"):
        u = c * a + s * (normal - cos_beta[..., None] * a) / sin_beta[..., None]
        uk = u[:, _FACES, _FACE_AXIS]
        rim = u * (plane / uk)[..., None]
    ok = (sign != 0.0) & (sin_beta > 1e-12) & (cos_beta < c) & (uk * sign > 1e-12)
    return np.concatenate((feet, np.where(ok[..., None], rim, np.nan)), axis=1)
