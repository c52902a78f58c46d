"""The triangular flock flown on vehicles: a planner step, then the team goes there.

The planner is given the set positions it asked for once the vehicles have settled there (the
thesis's exact-move assumption, kept honest by the tolerance), else the measured mocap positions.
"""

from __future__ import annotations

import math
from typing import Any

from gcs.mission.outcome import Outcome, gone_reason, path_length_m
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import STEP_FLOCK, flock_payload
from gcs.mission.report import MissionStatus
from gcs.mission.team import Team
from planners.flocking import FlockMission, FlockPlanner
from planners.geometry import Vec3


def fly_flock(f: Team, setup: PlannerSetup, hover: dict[int, Vec3]) -> Outcome:
    spec = f.spec
    ids = list(f.crafts)
    goal = spec.goal_n
    assert goal is not None
    individual = {ids[k]: g for k, g in enumerate(spec.goals_n[1:]) if k < len(ids)}
    lead = hover[ids[0]]
    heading = (goal[0] - lead[0], goal[1] - lead[1])
    planner = FlockPlanner(ids, FlockMission(goal, individual), heading, setup.params)
    pos = dict(hover)
    paths = {v: [p] for v, p in hover.items()}
    messages = 0
    reads = 0
    err_sq, err_n = 0.0, 0
    time_to_goal: dict[int, float | None] = dict.fromkeys(ids)
    for k in range(setup.max_steps):
        readings = {v: f.crafts[v].reading() for v in ids}
        out = planner.step(k, pos, readings)
        messages += out.messages_sent
        reads += out.state_reads
        for e in out.formation_samples:
            err_sq += e * e
            err_n += 1
        t = f.clock.now_s()
        f.rec.put(STEP_FLOCK, t, flock_payload(k, pos, readings, out))
        for v in ids:
            f.rec.pose(t, f.crafts[v].position_n(), v)
        arrived = planner.arrived()
        for v in ids:
            if arrived[v] and time_to_goal[v] is None:
                time_to_goal[v] = f.elapsed_s()
        if k % 5 == 0:
            f.say(f"step {k:4d} {out.phase.value:12s} arrived {sum(arrived.values())}/"
                  f"{len(ids)} messages {messages} min separation "
                  f"{f.min_separation_m:.2f} m")
        if all(arrived.values()):
            return Outcome(MissionStatus.REACHED, "every vehicle reached its goal", k,
                            paths[ids[0]], flock_metrics(f, (messages, reads), err_sq,
                                                          err_n, time_to_goal, paths))
        if gone := f.check():
            # the planner would go on planning round a teammate that no longer follows it
            return Outcome(MissionStatus.FAILED, gone_reason(gone), k, paths[ids[0]],
                            flock_metrics(f, (messages, reads), err_sq, err_n, time_to_goal,
                                          paths))
        if f.over_budget():
            break
        pos = f.go(dict(out.setpoints_n))
        for v in ids:
            paths[v].append(out.setpoints_n[v])
    short = [v for v, t in time_to_goal.items() if t is None]
    return Outcome(MissionStatus.FAILED, f"vehicles {short} short of their goals",
                    setup.max_steps, paths[ids[0]],
                    flock_metrics(f, (messages, reads), err_sq, err_n, time_to_goal, paths))


def flock_metrics(f: Team, messages: tuple[int, int], err_sq: float, err_n: int,
                   time_to_goal: dict[int, float | None], paths: dict[int, list[Vec3]]
                   ) -> dict[str, Any]:
    return {
        "vehicles": len(paths),
        "min_separation_m": f.min_separation_m,
        "messages_sent": messages[0],  # eq. 9.1's leader positions
        "state_reads": messages[1],  # the guard's and the coordination's reads of teammates
        "messages_total": sum(messages),
        "formation_error_m": math.sqrt(err_sq / err_n) if err_n else None,
        "time_to_goal_s": {str(v): t for v, t in time_to_goal.items()},
        "path_length_per_vehicle_m": {str(v): path_length_m(p) for v, p in paths.items()},
        "team_path_length_m": sum(path_length_m(p) for p in paths.values()),
    }
