"""Six IR proximity sensors (thesis §8.6): front, right, back, left, up, down; 0.5 m, 45° cones.

The sensors are body-fixed (FRD). The thesis's UAV keeps its yaw fixed and re-orients the sensor
indexes by its direction of travel instead of turning (Subfunction 2); `ProximityReading.along_n`
does that re-orientation for any yaw. A sensor reports the nearest return, as an IR ranger
reports the strongest (nearest) echo in its field of view. Simulated sensing either finds that
nearest point exactly (`ProximityParams.exact`, :mod:`planners.cone`) or casts a few rays per
cone, which is cheaper but can miss an edge that pokes into the cone between two rays.
"""

from __future__ import annotations

import enum
import functools
import math
from dataclasses import dataclass

import numpy as np

from planners.cone import boxes_in_cone_m, room_in_cone_m
from planners.geometry import Vec3, World


class Facing(enum.IntEnum):
    """Sensor facings; the values are MAVLink MAV_SENSOR_ORIENTATION numbers."""

    FRONT = 0
    RIGHT = 2
    BACK = 4
    LEFT = 6
    UP = 24
    DOWN = 25


# Sensor axes in the body frame FRD.
AXIS_B: dict[Facing, Vec3] = {
    Facing.FRONT: (1.0, 0.0, 0.0),
    Facing.RIGHT: (0.0, 1.0, 0.0),
    Facing.BACK: (-1.0, 0.0, 0.0),
    Facing.LEFT: (0.0, -1.0, 0.0),
    Facing.UP: (0.0, 0.0, -1.0),
    Facing.DOWN: (0.0, 0.0, 1.0),
}


@dataclass(frozen=True, slots=True)
class ProximityParams:
    """IR proximity sensor model (thesis §8.6 values as defaults)."""

    range_m: float = 0.5
    cone_deg: float = 45.0  # full cone angle
    rings: int = 2  # rings of rays around the axis, out to the cone edge
    rays_per_ring: int = 8
    noise_sigma_m: float = 0.0  # the thesis assumes exact readings; SITL worlds add >= 0.01
    # The nearest surface anywhere inside the cone (the thesis's sensor, and what EPBHA's memory
    # takes a reading to mean) instead of the nearest of the rays above.
    exact: bool = False

    def __post_init__(self) -> None:
        if not self.range_m > 0.0:
            raise ValueError(f"proximity range_m must be > 0, got {self.range_m}")
        if not 0.0 <= self.cone_deg < 180.0:
            raise ValueError(f"proximity cone_deg must be in [0, 180), got {self.cone_deg}")
        if self.rings < 0 or self.rays_per_ring < 1:
            raise ValueError("proximity rings must be >= 0 and rays_per_ring >= 1")
        if self.noise_sigma_m < 0.0:
            raise ValueError(f"proximity noise_sigma_m must be >= 0, got {self.noise_sigma_m}")


@dataclass(frozen=True, slots=True)
class ProximityReading:
    """Distances (m) seen by the six sensors, None where nothing is inside cone and range.

    `yaw_rad` is the vehicle's heading when the reading was taken (0 = front points north).
    """

    front_m: float | None
    right_m: float | None
    back_m: float | None
    left_m: float | None
    up_m: float | None
    down_m: float | None
    yaw_rad: float = 0.0

    @classmethod
    def from_facings(
        cls, values: dict[Facing, float | None], yaw_rad: float = 0.0
    ) -> ProximityReading:
        """Build a reading from per-facing distances; missing facings see nothing."""
        return cls(
            values.get(Facing.FRONT),
            values.get(Facing.RIGHT),
            values.get(Facing.BACK),
            values.get(Facing.LEFT),
            values.get(Facing.UP),
            values.get(Facing.DOWN),
            yaw_rad,
        )

    @classmethod
    def clear(cls) -> ProximityReading:
        """A reading where no sensor sees anything."""
        return cls(None, None, None, None, None, None)

    def get(self, facing: Facing) -> float | None:
        """The distance seen by one sensor."""
        return (
            self.front_m,
            self.right_m,
            self.back_m,
            self.left_m,
            self.up_m,
            self.down_m,
        )[_INDEX[facing]]

    def facing_toward(self, direction_n: Vec3) -> Facing:
        """The sensor whose axis, at this reading's yaw, points most nearly along `direction_n`."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        best, best_dot = Facing.FRONT, -math.inf
        for facing, (fx, fy, fz) in AXIS_B.items():
            nx, ny = c * fx - s * fy, s * fx + c * fy
            dot = nx * direction_n[0] + ny * direction_n[1] + fz * direction_n[2]
            if dot > best_dot:
                best, best_dot = facing, dot
        return best

    def along_n(self, direction_n: Vec3) -> float | None:
        """The distance seen in a NED direction (the re-orientation of Subfunction 2)."""
        return self.get(self.facing_toward(direction_n))

    def active(self, range_m: float) -> frozenset[Facing]:
        """Facings that see something within `range_m`."""
        return frozenset(f for f in Facing if (v := self.get(f)) is not None and v <= range_m)


_INDEX = {
    Facing.FRONT: 0,
    Facing.RIGHT: 1,
    Facing.BACK: 2,
    Facing.LEFT: 3,
    Facing.UP: 4,
    Facing.DOWN: 5,
}


def _perpendiculars(axis: Vec3) -> tuple[Vec3, Vec3]:
    a = np.asarray(axis, dtype=float)
    helper = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(a, helper)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    return (tuple(u.tolist()), tuple(v.tolist()))


def cone_rays_b(facing: Facing, params: ProximityParams) -> list[Vec3]:
    """Unit ray directions (body FRD) sampling one sensor's cone: its axis plus rings."""
    axis = AXIS_B[facing]
    u, v = _perpendiculars(axis)
    half = math.radians(params.cone_deg) / 2.0
    rays: list[Vec3] = [axis]
    for ring in range(1, params.rings + 1):
        theta = half * ring / params.rings
        ct, st = math.cos(theta), math.sin(theta)
        for k in range(params.rays_per_ring):
            phi = 2.0 * math.pi * k / params.rays_per_ring
            cp, sp = math.cos(phi), math.sin(phi)
            rays.append(
                tuple(  # type: ignore[arg-type]
                    ct * axis[i] + st * (cp * u[i] + sp * v[i]) for i in range(3)
                )
            )
    return rays


def sense(
    world: World,
    pos_n: Vec3,
    yaw_rad: float = 0.0,
    params: ProximityParams | None = None,
    rng: np.random.Generator | None = None,
) -> ProximityReading:
    """Ray-cast the six cones from `pos_n`; noise only when `rng` is given and sigma > 0."""
    params = params or ProximityParams()
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    values: dict[Facing, float | None] = {}
    exact = _ExactCones(world, pos_n, params) if params.exact else None
    for facing in Facing:
        nearest: float | None = None
        if exact is not None:
            fx, fy, fz = AXIS_B[facing]
            nearest = exact.nearest((c * fx - s * fy, s * fx + c * fy, fz))
        else:
            for fx, fy, fz in _rays_for(facing, params):
                ray_n = (c * fx - s * fy, s * fx + c * fy, fz)
                hit = world.ray_cast(pos_n, ray_n, params.range_m if nearest is None else nearest)
                if hit is not None and (nearest is None or hit < nearest):
                    nearest = hit
        if nearest is not None and rng is not None and params.noise_sigma_m > 0.0:
            nearest = min(params.range_m, max(0.0, nearest + rng.normal(0.0, params.noise_sigma_m)))
        values[facing] = nearest
    return ProximityReading.from_facings(values, yaw_rad)


@functools.lru_cache(maxsize=64)
def _rays_for(facing: Facing, params: ProximityParams) -> tuple[Vec3, ...]:
    return tuple(cone_rays_b(facing, params))


class _ExactCones:
    """The boxes within sensor range of one position, ready for exact cone queries."""

    def __init__(self, world: World, pos_n: Vec3, params: ProximityParams) -> None:
        self._room, self._pos = world.room, pos_n
        self._in_room = world.room.contains(pos_n)
        self._half = math.radians(params.cone_deg) / 2.0
        self._range = params.range_m
        p = np.asarray(pos_n, dtype=float)
        near = [b for b in world.obstacles if b.distance_to_point(pos_n) <= params.range_m]
        self._lo = np.array([b.min_n for b in near], dtype=float).reshape(-1, 3) - p
        self._hi = np.array([b.max_n for b in near], dtype=float).reshape(-1, 3) - p

    def nearest(self, axis_n: Vec3) -> float | None:
        """The nearest obstacle or wall point inside the cone about `axis_n`, within range."""
        found = [
            d
            for d in (
                boxes_in_cone_m(self._lo, self._hi, axis_n, self._half),
                room_in_cone_m(self._room, self._pos, axis_n, self._half)
                if self._in_room else None,
            )
            if d is not None and d <= self._range
        ]
        return min(found, default=None)
