"""Reynolds-style flocking baseline: separation, alignment, cohesion, plus a goal and IR repulsion.

Every vehicle senses every teammate's position and velocity (all-to-all state sharing), so each
step costs N·(N−1) messages. Each vehicle steers towards the same final target the triangular
flock gives it (its individual goal or its slot round the common goal), so both planners are
scored on the same task. Obstacles are felt only through the six IR sensors, as repulsion away
from any sensor that sees something. There is no guard: separation is Reynolds's own rule, so
the baseline's collisions and minimum separation are its own.

Reference: C. W. Reynolds, "Flocks, herds and schools: a distributed behavioral model", 1987.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from planners.flocking.formation import Formation, FormationParams, role_of, rotate_f_to_n
from planners.flocking.planner import FlockMission
from planners.flocking.types import FlockStep, Phase, VehicleMode
from planners.geometry import Vec3
from planners.proximity import AXIS_B, Facing, ProximityReading


@dataclass(frozen=True, slots=True)
class ReynoldsParams:
    """Weights and radii of the three rules, the goal term and obstacle repulsion."""

    max_step_m: float = 0.1  # same nominal speed as the flock's grid step
    separation_radius_m: float = 0.8
    neighbour_radius_m: float = 2.0
    w_separation: float = 1.5
    w_alignment: float = 0.3
    w_cohesion: float = 0.2
    w_goal: float = 1.0
    w_obstacle: float = 2.5
    sensing_range_m: float = 0.5
    goal_tolerance_m: float = 0.05
    formation: FormationParams = field(default_factory=FormationParams)

    def __post_init__(self) -> None:
        if self.max_step_m <= 0.0:
            raise ValueError(f"max_step_m must be > 0, got {self.max_step_m}")


class ReynoldsPlanner:
    """All-to-all Reynolds flock with a per-vehicle goal."""

    name = "reynolds"

    def __init__(
        self,
        vehicle_ids: list[int],
        targets_n: dict[int, Vec3],
        start_offsets_n: dict[int, np.ndarray],
        params: ReynoldsParams | None = None,
    ) -> None:
        if not vehicle_ids or set(targets_n) != set(vehicle_ids):
            raise ValueError("every vehicle needs exactly one target")
        self.params = params or ReynoldsParams()
        self.ids = list(vehicle_ids)
        self._targets = {v: np.asarray(targets_n[v], dtype=float) for v in self.ids}
        self._offsets = start_offsets_n
        self._prev: dict[int, np.ndarray] | None = None
        self._arrived = dict.fromkeys(self.ids, False)

    @classmethod
    def for_mission(
        cls,
        vehicle_ids: list[int],
        mission: FlockMission,
        heading_n: tuple[float, float],
        params: ReynoldsParams | None = None,
    ) -> ReynoldsPlanner:
        """Targets and start layout identical to the triangular flock's."""
        prm = params or ReynoldsParams()
        form = Formation.build(len(vehicle_ids), prm.formation)
        g = mission.common_goal_n
        targets: dict[int, Vec3] = {}
        offsets: dict[int, np.ndarray] = {}
        for k, v in enumerate(vehicle_ids):
            off = rotate_f_to_n(form.offsets_f[k], np.asarray(heading_n, dtype=float))
            offsets[v] = off
            targets[v] = mission.individual_goals_n.get(v, (g[0] + off[0], g[1] + off[1], g[2]))
        return cls(vehicle_ids, targets, offsets, prm)

    def final_targets_n(self) -> dict[int, Vec3]:
        """Each vehicle's target."""
        out: dict[int, Vec3] = {}
        for v in self.ids:
            x, y, z = (float(c) for c in self._targets[v])
            out[v] = (x, y, z)
        return out

    def start_positions_n(self, leader_start_n: Vec3) -> dict[int, Vec3]:
        """The same starting layout as the triangular flock."""
        return {
            v: (leader_start_n[0] + o[0], leader_start_n[1] + o[1], leader_start_n[2])
            for v, o in self._offsets.items()
        }

    def arrived(self) -> dict[int, bool]:
        """Whether each vehicle is at its target."""
        return dict(self._arrived)

    def step(
        self,
        step_index: int,
        positions_n: dict[int, Vec3],
        readings: dict[int, ProximityReading],
    ) -> FlockStep:
        """One Reynolds update for every vehicle, in the flock's step type: each vehicle's
        role is its formation slot's (the baseline starts from and ends on the same slots),
        every teammate's state already arrives in the N·(N−1) messages (no further reads)."""
        prm = self.params
        pos = {v: np.asarray(positions_n[v], dtype=float) for v in self.ids}
        vel = {
            v: (pos[v] - self._prev[v]) if self._prev is not None else np.zeros(3) for v in self.ids
        }
        out: dict[int, Vec3] = {}
        for v in self.ids:
            p = pos[v]
            sep = np.zeros(3)
            coh = np.zeros(3)
            ali = np.zeros(3)
            n_nb = 0
            for u in self.ids:
                if u == v:
                    continue
                d = p - pos[u]
                r = float(np.linalg.norm(d))
                if r < prm.separation_radius_m and r > 1e-9:
                    sep += d / r * (prm.separation_radius_m - r) / prm.separation_radius_m
                if r < prm.neighbour_radius_m:
                    coh += pos[u]
                    ali += vel[u]
                    n_nb += 1
            if n_nb:
                coh = coh / n_nb - p
                ali = ali / n_nb
            to_goal = self._targets[v] - p
            dist = float(np.linalg.norm(to_goal))
            goal = to_goal / dist if dist > 1e-9 else np.zeros(3)
            obs = np.zeros(3)
            for facing in Facing:
                seen_m = readings[v].get(facing)
                if seen_m is not None and seen_m < prm.sensing_range_m:
                    push = (prm.sensing_range_m - seen_m) / prm.sensing_range_m
                    obs -= np.asarray(AXIS_B[facing]) * push
            steer = (
                prm.w_separation * sep
                + prm.w_alignment * ali / max(prm.max_step_m, 1e-9)
                + prm.w_cohesion * coh
                + prm.w_goal * goal
                + prm.w_obstacle * obs
            )
            norm = float(np.linalg.norm(steer))
            step = min(prm.max_step_m, dist)
            new = p + (steer / norm * step if norm > 1e-9 else np.zeros(3))
            # judged where the vehicle is, not where it is sent: the mission loop flies no plan
            # after the one that finds every vehicle arrived
            self._arrived[v] = dist <= prm.goal_tolerance_m
            out[v] = (float(new[0]), float(new[1]), float(new[2]))
        self._prev = pos
        n = len(self.ids)
        return FlockStep(
            setpoints_n=out, messages_sent=n * (n - 1),
            modes={v: VehicleMode.ARRIVED if self._arrived[v] else VehicleMode.FORMATION
                   for v in self.ids},
            roles={v: role_of(k, n) for k, v in enumerate(self.ids)},
            phase=Phase.COMMON_GOAL, formation_error_m=None, formation_samples=(),
            leader_avoiding=False, held_by_guard=())
