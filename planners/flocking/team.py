"""The triangular flock's team: its vehicles, formation, goals and per-vehicle state, what the
planner steps (:mod:`planners.flocking.planner`) and what the mission loop reads of it."""

from __future__ import annotations

import numpy as np

from planners.epbha.planner import Epbha
from planners.flocking.comm import OpenLoopChannel
from planners.flocking.formation import Formation, rotate_f_to_n
from planners.flocking.guard import FlockGuard
from planners.flocking.moves import AxisMoves
from planners.flocking.params import FlockParams
from planners.flocking.types import FlockMission, Phase, VehicleState
from planners.geometry import Vec3


class FlockTeam:
    """The team the triangular flock plans for (the planner's base)."""

    def __init__(
        self,
        vehicle_ids: list[int],
        mission: FlockMission,
        heading_n: tuple[float, float],
        params: FlockParams | None = None,
    ) -> None:
        if len(set(vehicle_ids)) != len(vehicle_ids) or not vehicle_ids:
            raise ValueError(f"vehicle_ids must be unique and non-empty, got {vehicle_ids}")
        unknown = set(mission.individual_goals_n) - set(vehicle_ids)
        if unknown:
            raise ValueError(f"individual goals for unknown vehicle ids {sorted(unknown)}")
        self.params = params or FlockParams()
        self.ids = list(vehicle_ids)
        self.n = len(vehicle_ids)
        self.mission = mission
        self.heading_n = np.asarray(heading_n, dtype=float)
        self.formation = Formation.build(self.n, self.params.formation)
        self.channel = OpenLoopChannel(latency_steps=self.params.latency_steps)
        self.phase = Phase.COMMON_GOAL
        self._wait_at_common = 0
        self._states = [VehicleState() for _ in range(self.n)]
        self._guard = FlockGuard(self.params, self._states)
        self._moves = AxisMoves(self.params, self._guard)
        self._epbha: Epbha | None = None
        self._epbha_failed = False
        g = mission.common_goal_n
        self._final_n: list[Vec3] = []
        for k in range(self.n):
            vid = self.ids[k]
            if vid in mission.individual_goals_n:
                self._final_n.append(tuple(map(float, mission.individual_goals_n[vid])))  # type: ignore[arg-type]
            else:
                off = rotate_f_to_n(self.formation.offsets_f[k], self.heading_n)
                self._final_n.append((g[0] + off[0], g[1] + off[1], g[2]))

    # ----- public helpers -------------------------------------------------------------------

    def final_targets_n(self) -> dict[int, Vec3]:
        """Where each vehicle ends: its individual goal, or its slot around the common goal."""
        return {self.ids[k]: self._final_n[k] for k in range(self.n)}

    def start_positions_n(self, leader_start_n: Vec3) -> dict[int, Vec3]:
        """Formation slots around the root's start, for placing the team before take-off."""
        out: dict[int, Vec3] = {}
        for k in range(self.n):
            off = rotate_f_to_n(self.formation.offsets_f[k], self.heading_n)
            out[self.ids[k]] = (
                leader_start_n[0] + off[0],
                leader_start_n[1] + off[1],
                leader_start_n[2],
            )
        return out

    def arrived(self) -> dict[int, bool]:
        """Whether each vehicle has reached its final target."""
        return {self.ids[k]: self._states[k].arrived_final for k in range(self.n)}

    def _formation_samples(self, pos: list[Vec3]) -> list[float]:
        """Horizontal distance of each follower in formation from its slot behind its leader."""
        if self.phase is not Phase.COMMON_GOAL:
            return []
        out: list[float] = []
        for k in range(1, self.n):
            st = self._states[k]
            if st.in_trail or st.avoid_dir is not None or st.goal_n is None:
                continue
            par = self.formation.parent(k)
            assert par is not None
            if self._states[par].in_trail or self._states[par].avoid_dir is not None:
                continue
            slot = self.formation.slot_n(k, np.array(pos[par][:2]), self.heading_n)
            out.append(float(np.hypot(pos[k][0] - slot[0], pos[k][1] - slot[1])))
        return out
