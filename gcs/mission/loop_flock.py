"""The triangular flock's mission loop, one for every backend: sense, plan, the team goes there.

The planner is given the set positions it asked for once the vehicles have settled there (the
thesis's exact-move assumption, kept honest by the tolerance), else the measured positions; in
the kinematic world the two are the same. The loop stops when every vehicle has arrived, or as
soon as one is taken off the mission: the planner would go on planning round a teammate that
no longer follows it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from gcs.mission.outcome import Outcome, gone_reason, path_length_m
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.port import ObstaclePort
from gcs.mission.recording import STEP_FLOCK, flock_payload
from gcs.mission.report import MissionStatus
from planners.flocking.planner import FlockMission, FlockPlanner
from planners.flocking.swarm import SwarmPlanner
from planners.geometry import Vec3

LOOP = "flock"


@dataclass(slots=True)
class _Tally:
    """The flock's communication and formation books over the loop."""

    messages: int = 0
    reads: int = 0
    err_sq: float = 0.0
    err_n: int = 0
    time_to_goal: dict[int, float | None] = field(default_factory=dict)


def fly_flock(port: ObstaclePort, setup: PlannerSetup, start_n: dict[int, Vec3],
              planner: SwarmPlanner | None = None) -> Outcome:
    """Fly the port's vehicles (the root leader first) from `start_n` to the mission's goals
    with `planner`, by default the triangular flock the mission and its setup describe."""
    spec = port.spec
    ids = list(port.vehicles())
    if planner is None:
        goal = spec.goal_n
        assert goal is not None
        individual = {ids[k]: g for k, g in enumerate(spec.goals_n[1:]) if k < len(ids)}
        lead = start_n[ids[0]]
        heading = (goal[0] - lead[0], goal[1] - lead[1])
        planner = FlockPlanner(ids, FlockMission(goal, individual), heading, setup.params)
    pos = {v: start_n[v] for v in ids}
    paths = {v: [start_n[v]] for v in ids}
    tally = _Tally(time_to_goal=dict.fromkeys(ids))

    def done(status: MissionStatus, reason: str) -> Outcome:
        return Outcome(status, reason, len(paths[ids[0]]) - 1, paths[ids[0]],
                       _metrics(port, tally, paths), loop=LOOP)

    for k in range(setup.max_steps + 1):
        readings = {v: port.reading(v) for v in ids}
        out = planner.step(k, pos, readings)
        tally.messages += out.messages_sent
        tally.reads += out.state_reads
        for e in out.formation_samples:
            tally.err_sq += e * e
            tally.err_n += 1
        t = port.now_s()
        port.rec.put(STEP_FLOCK, t, flock_payload(k, pos, readings, out))
        for v in ids:
            port.rec.pose(t, port.position_n(v), v)
        arrived = planner.arrived()
        for v in ids:
            if arrived[v] and tally.time_to_goal[v] is None:
                tally.time_to_goal[v] = port.elapsed_s()
        if k % 5 == 0:
            port.say(f"step {k:4d} {out.phase.value:12s} arrived {sum(arrived.values())}/"
                     f"{len(ids)} messages {tally.messages} min separation "
                     f"{port.min_separation_m():.2f} m")
        if all(arrived.values()):
            return done(MissionStatus.REACHED, "every vehicle reached its goal")
        if gone := port.check():
            return done(MissionStatus.FAILED, gone_reason(gone))
        if port.over_budget() or k == setup.max_steps:
            break
        pos = port.go(dict(out.setpoints_n))
        for v in ids:
            paths[v].append(out.setpoints_n[v])
    short = [v for v, t in tally.time_to_goal.items() if t is None]
    return done(MissionStatus.FAILED, f"vehicles {short} short of their goals")


def _metrics(port: ObstaclePort, tally: _Tally, paths: dict[int, list[Vec3]]) -> dict[str, Any]:
    return {
        "vehicles": len(paths),
        "min_separation_m": port.min_separation_m(),
        "messages_sent": tally.messages,  # eq. 9.1's leader positions
        "state_reads": tally.reads,  # the guard's and the coordination's reads of teammates
        "messages_total": tally.messages + tally.reads,
        "formation_error_m": math.sqrt(tally.err_sq / tally.err_n) if tally.err_n else None,
        "time_to_goal_s": {str(v): t for v, t in tally.time_to_goal.items()},
        "path_length_per_vehicle_m": {str(v): path_length_m(p) for v, p in paths.items()},
        "team_path_length_m": sum(path_length_m(p) for p in paths.values()),
    }
