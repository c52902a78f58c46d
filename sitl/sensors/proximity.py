"""Six body-fixed IR rangers (front, right, back, left, up, down): 0.5 m, 45° cone (thesis §8.6).

A sensor reports the distance to the nearest surface inside its cone and range, else nothing.
Room surfaces are planes, so the nearest point of a plane inside a cone is found exactly: the
cone ray closest to the plane's normal hits it at D / cos(max(β − θ, 0)), with D the
perpendicular distance, β the angle between cone axis and normal and θ the half-angle. Boxes are
found by casting rays: the axis, a ring on the cone's edge and a ring at half its angle. The
sensors sit at the centre of gravity and look straight along the body axes (§8.6 suggests tilting
them 15–30° off the body surface; the planners here assume the axes, so the tilt is left out).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence

import numpy as np

from sitl.geometry import (
    CEILING,
    FLOOR,
    WALL_EAST,
    WALL_NORTH,
    WALL_SOUTH,
    WALL_WEST,
    BoxT,
    Geometry,
)
from sitl.rotation import Quat, Vec3, rotate_b_to_n
from sitl.sensor_params import ProximityParams
from sitl.tick_record import tick_record


class ProximityFacing(enum.IntEnum):
    """Mounting direction as MAV_SENSOR_ORIENTATION."""

    FRONT = 0
    RIGHT = 2
    BACK = 4
    LEFT = 6
    UP = 24
    DOWN = 25


FACING_AXIS_B: dict[ProximityFacing, Vec3] = {
    ProximityFacing.FRONT: (1.0, 0.0, 0.0),
    ProximityFacing.RIGHT: (0.0, 1.0, 0.0),
    ProximityFacing.BACK: (-1.0, 0.0, 0.0),
    ProximityFacing.LEFT: (0.0, -1.0, 0.0),
    ProximityFacing.UP: (0.0, 0.0, -1.0),
    ProximityFacing.DOWN: (0.0, 0.0, 1.0),
}


@tick_record
class ProximitySample:
    """One IR reading; distance_m is None when nothing is inside the cone and range."""

    facing: ProximityFacing
    distance_m: float | None
    max_m: float
    target: str | None = None  # name of the surface seen (truth, for tests and logs)


def _perpendicular(a: Vec3) -> tuple[Vec3, Vec3]:
    ax, ay, az = a
    helper = (0.0, 0.0, 1.0) if abs(az) < 0.9 else (1.0, 0.0, 0.0)
    ux = ay * helper[2] - az * helper[1]
    uy = az * helper[0] - ax * helper[2]
    uz = ax * helper[1] - ay * helper[0]
    n = math.sqrt(ux * ux + uy * uy + uz * uz)
    u = (ux / n, uy / n, uz / n)
    v = (ay * u[2] - az * u[1], az * u[0] - ax * u[2], ax * u[1] - ay * u[0])
    return u, v


def cone_rays_b(axis_b: Vec3, half_angle_rad: float, per_ring: int) -> tuple[Vec3, ...]:
    """Unit rays in the body frame: the axis, then rings at the half-angle and half of it."""
    u, v = _perpendicular(axis_b)
    rays = [axis_b]
    for ang in (half_angle_rad, half_angle_rad / 2.0):
        ca, sa = math.cos(ang), math.sin(ang)
        for k in range(per_ring):
            phi = 2.0 * math.pi * k / per_ring
            cp, sp = math.cos(phi) * sa, math.sin(phi) * sa
            rays.append(
                (
                    ca * axis_b[0] + cp * u[0] + sp * v[0],
                    ca * axis_b[1] + cp * u[1] + sp * v[1],
                    ca * axis_b[2] + cp * u[2] + sp * v[2],
                )
            )
    return tuple(rays)


class ProximityModel:
    """The six rangers of the companion sensor board."""

    def __init__(
        self, params: ProximityParams, rng: np.random.Generator, noise: bool = True
    ) -> None:
        self.params = params
        self.rng = rng
        self.noise = noise
        self.half_angle_rad = math.radians(params.cone_deg) / 2.0
        self._rays = {
            f: cone_rays_b(a, self.half_angle_rad, params.rays_per_ring)
            for f, a in FACING_AXIS_B.items()
        }

    def _planes(self, geom: Geometry, o: Vec3) -> tuple[tuple[Vec3, float, str], ...]:
        ox, oy, oz = o
        return (
            ((1.0, 0.0, 0.0), geom.rx1 - ox, WALL_NORTH),
            ((-1.0, 0.0, 0.0), ox - geom.rx0, WALL_SOUTH),
            ((0.0, 1.0, 0.0), geom.ry1 - oy, WALL_EAST),
            ((0.0, -1.0, 0.0), oy - geom.ry0, WALL_WEST),
            ((0.0, 0.0, 1.0), geom.rz1 - oz, FLOOR),
            ((0.0, 0.0, -1.0), oz - geom.rz0, CEILING),
        )

    def sample(
        self, geom: Geometry, pos_n: Vec3, q_nb: Quat, extra_boxes: Sequence[BoxT] = ()
    ) -> list[ProximitySample]:
        """The six readings (front, right, back, left, up, down) at pose (pos_n, q_nb).

        `extra_boxes` are further solids for this reading only (e.g. other vehicles' bodies).
        """
        prm = self.params
        max_m = prm.max_m
        ox, oy, oz = pos_n
        planes = [pl for pl in self._planes(geom, pos_n) if pl[1] <= max_m]
        boxes = [
            b for b in (*geom.boxes, *extra_boxes) if geom.box_distance(b, ox, oy, oz) <= max_m
        ]
        out: list[ProximitySample] = []
        cos_theta = math.cos(self.half_angle_rad)
        for facing, axis_b in FACING_AXIS_B.items():
            best, target = math.inf, None
            if planes or boxes:
                ax, ay, az = rotate_b_to_n(q_nb, axis_b)
                for (nx, ny, nz), dist, name in planes:
                    cb = ax * nx + ay * ny + az * nz
                    if cb >= cos_theta:
                        d = max(dist, 0.0)
                    else:
                        beta = math.acos(max(-1.0, min(1.0, cb)))
                        gamma = beta - self.half_angle_rad
                        if gamma >= math.pi / 2.0:
                            continue
                        d = max(dist, 0.0) / math.cos(gamma)
                    if d < best:
                        best, target = d, name
                if boxes:
                    for ray_b in self._rays[facing]:
                        dx, dy, dz = rotate_b_to_n(q_nb, ray_b)
                        for b in boxes:
                            t = geom.ray_box(b, ox, oy, oz, dx, dy, dz)
                            if t < best:
                                best, target = t, b[6]
            if best > max_m:
                out.append(ProximitySample(facing, None, max_m, None))
                continue
            if self.noise:
                best += prm.noise_m * float(self.rng.standard_normal())
            out.append(ProximitySample(facing, min(max(best, 0.0), max_m), max_m, target))
        return out
