"""The planners' kinematic world behind the mission port: exact moves on a nominal timeline.

Every set position is reached exactly (`planners.kinematic.KinematicSim` keeps the safety
books of each move). Mission time advances by a fixed time per planner move (`step_s`, the
obstacle planners' nominal step time) or, without one, by the leg's length at `speed_mps`, and
by each detector count's own time; recordings are stamped on that timeline.

A team's separation is checked on the continuous straight moves between steps (the exact
closest approach of two linear motions), so `min_separation_m` is the true minimum, and two
centres closer than the frame's diagonal at the end of a move are a vehicle collision.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.port import Count
from gcs.mission.recording import MissionRecording
from gcs.mission.report import RunMode
from gcs.mission.spec import MissionSpec
from planners.flocking.separation import VEHICLE_COLLISION_M, pairwise_min_m
from planners.geometry import Vec3
from planners.kinematic import KinematicSim
from planners.proximity import ProximityReading
from planners.radiation import RadiationMapperParams, take_reading
from planners.radiation.field import RadiationField


class KinematicPort:
    """Vehicles of the kinematic world; a radiation `field` (and its `rng`) for a detector."""

    mode = RunMode.KINEMATIC

    def __init__(self, spec: MissionSpec, rec: MissionRecording, sims: dict[int, KinematicSim],
                 t0_s: float, *, step_s: float | None = None, speed_mps: float = 1.0,
                 field: RadiationField | None = None, rng: np.random.Generator | None = None,
                 progress: Callable[[str], None] | None = None,
                 vehicle_collision_m: float = VEHICLE_COLLISION_M) -> None:
        self.spec = spec
        self.rec = rec
        self.sims = sims
        self.t0_s = t0_s
        self.step_s = step_s
        self.speed_mps = speed_mps
        self.field = field
        self.rng = rng
        self._t_s = 0.0  # legs at speed and detector counts
        self._moves = 0  # planner moves of `step_s` each: counted, not summed, to stay exact
        self._progress = progress
        self._events = EventLog(rec, progress)
        self.vehicle_collision_m = vehicle_collision_m
        self.vehicle_collisions = 0
        self._touching: set[tuple[int, int]] = set()
        self._min_sep_m = pairwise_min_m(self._positions(), self._positions()) \
            if len(sims) > 1 else math.inf

    def _positions(self) -> np.ndarray:
        return np.array([s.pos_n for s in self.sims.values()], dtype=float)

    def vehicles(self) -> tuple[int, ...]:
        return tuple(self.sims)

    def now_s(self) -> float:
        return self.t0_s + self.elapsed_s()

    def elapsed_s(self) -> float:
        if self.step_s is None:
            return self._t_s
        return self._t_s + self._moves * self.step_s

    def min_separation_m(self) -> float:
        return self._min_sep_m

    def over_budget(self) -> bool:
        # the thesis's world counts planner steps, not seconds: `max_steps` bounds it
        return False

    def say(self, line: str) -> None:
        if self._progress is not None:
            self._progress(line)

    def event(self, what: MissionEvent, vehicle: int | None = None, detail: str = "") -> None:
        self._events(self.now_s(), what, vehicle, detail)

    def position_n(self, vehicle: int) -> Vec3:
        return self.sims[vehicle].pos_n

    def reading(self, vehicle: int) -> ProximityReading:
        return self.sims[vehicle].sense()

    def go(self, targets_n: dict[int, Vec3],
           timeout_s: float | None = None) -> dict[int, Vec3]:
        longest = 0.0
        before = self._positions()
        for v, target in targets_n.items():
            sim = self.sims[v]
            longest = max(longest, math.dist(sim.pos_n, target))
            sim.move_to(target)
        if len(self.sims) > 1:
            self._separation(before, self._positions())
        if self.step_s is not None:
            self._moves += 1
        else:
            self._t_s += longest / self.speed_mps
        return {v: self.sims[v].pos_n for v in targets_n}

    def _separation(self, before: np.ndarray, after: np.ndarray) -> None:
        self._min_sep_m = min(self._min_sep_m, pairwise_min_m(before, after))
        d_end = np.linalg.norm(after[:, None] - after[None], axis=2)
        now = {(int(i), int(j)) for i, j in np.argwhere(d_end < self.vehicle_collision_m)
               if i < j}
        self.vehicle_collisions += len(now - self._touching)
        self._touching = now

    def check(self) -> dict[int, str]:
        return {}

    def count(self, vehicle: int, p: RadiationMapperParams) -> Count:
        if self.field is None or self.rng is None:
            raise ValueError("a kinematic port without a radiation field has no detector")
        at = self.sims[vehicle].pos_n
        cps, dwell_s = take_reading(self.field, np.asarray(at[:2], dtype=float), self.rng, p)
        self._t_s += dwell_s
        return Count(cps, dwell_s, at)

    def off_mission(self, vehicle: int) -> str | None:
        return None

    def fly_to_sample(self, vehicle: int, target_n: Vec3, p: RadiationMapperParams,
                      count_s: float, timeout_s: float) -> bool:
        sim = self.sims[vehicle]
        self._t_s += math.dist(sim.pos_n[:2], target_n[:2]) / self.speed_mps
        sim.move_to(target_n)
        return True
