"""EPBHA and the triangular flock flown on vehicles: a planner step, then the team goes there.

The planner is given the set position it asked for once the vehicle has settled there (the
thesis's exact-move assumption, kept honest by the tolerance), else the measured mocap position.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import STEP_EPBHA, STEP_FLOCK, epbha_payload, flock_payload
from gcs.mission.report import MissionStatus
from gcs.mission.team import Team
from planners.epbha import Epbha, Status
from planners.flocking import FlockMission, FlockPlanner
from planners.geometry import Vec3


@dataclass(slots=True)
class Outcome:
    """How a planner's part of a mission ended, and what it measured."""

    status: MissionStatus
    reason: str
    steps: int
    path_n: list[Vec3]
    metrics: dict[str, Any] = field(default_factory=dict)
    products: Any = None


def _why(gone: dict[int, str]) -> str:
    return "; ".join(f"vehicle {v}: {why}" for v, why in sorted(gone.items()))


def path_length_m(path: list[Vec3]) -> float:
    """Length of a polyline in metres."""
    return sum(math.dist(a, b) for a, b in itertools.pairwise(path))


def fly_epbha(f: Team, setup: PlannerSetup, hover: dict[int, Vec3]) -> Outcome:
    spec = f.spec
    v = next(iter(f.crafts))
    craft = f.crafts[v]
    goal = spec.goal_n
    assert goal is not None
    start = hover[v]
    planner = Epbha(setup.params, goal, start)
    pos = start
    path = [start]
    for k in range(setup.max_steps + 1):
        reading = craft.reading()
        measured = craft.position_n()
        decision = planner.step(pos, reading)
        payload = epbha_payload(k, pos, reading, decision, planner.cost_evaluations)
        payload["measured"] = {"x": measured[0], "y": measured[1], "z": measured[2]}
        t = f.clock.now_s()
        f.rec.put(STEP_EPBHA, t, payload)
        f.rec.pose(t, measured)
        f.say(f"step {k:4d} at ({measured[0]:+.2f}, {measured[1]:+.2f}, alt "
              f"{-measured[2]:.2f}) {decision.status.value:8s} {decision.reason.value} "
              f"[{decision.obstacle.value}]")
        if decision.status is Status.REACHED:
            err = math.dist(measured, goal)
            ok = err <= spec.goal_tolerance_m
            return Outcome(MissionStatus.REACHED if ok else MissionStatus.FAILED,
                            "goal reached" if ok else f"stopped {err:.2f} m from the goal",
                            k, path, {"cost_evaluations": planner.cost_evaluations,
                                      "goal_error_m": err})
        if decision.status is Status.DEADLOCK:
            return Outcome(MissionStatus.FAILED, decision.reason.value, k, path,
                            {"cost_evaluations": planner.cost_evaluations})
        if gone := f.check():
            return Outcome(MissionStatus.FAILED, _why(gone), k, path,
                            {"cost_evaluations": planner.cost_evaluations})
        if f.over_budget():
            break
        pos = f.go({v: decision.next_pos_n})[v]
        path.append(decision.next_pos_n)
    return Outcome(MissionStatus.FAILED, f"no goal within {setup.max_steps} steps or "
                    f"{spec.max_duration_s:g} s", len(path) - 1, path,
                    {"cost_evaluations": planner.cost_evaluations})


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
            return Outcome(MissionStatus.FAILED, _why(gone), k, paths[ids[0]],
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
