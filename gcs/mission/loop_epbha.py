"""EPBHA's mission loop, one for every backend: sense, plan a step, go there, repeat.

The planner is given the set position it asked for once the vehicle has settled there (the
thesis's exact-move assumption, kept honest by the tolerance), else the measured position; in
the kinematic world the two are the same. Every step is recorded as `STEP_EPBHA` with the
measured position beside the planner's.
"""

from __future__ import annotations

import math

from gcs.mission.outcome import Outcome, gone_reason
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.port import ObstaclePort
from gcs.mission.recording import STEP_EPBHA, epbha_payload, xyz
from gcs.mission.report import MissionStatus
from planners.epbha.planner import Epbha, Status
from planners.geometry import Vec3

LOOP = "epbha"


def fly_epbha(port: ObstaclePort, setup: PlannerSetup, start_n: Vec3) -> Outcome:
    """Fly the port's first vehicle from `start_n` (where it hovers) to the mission's goal."""
    spec = port.spec
    goal = spec.goal_n
    assert goal is not None
    v = port.vehicles()[0]
    planner = Epbha(setup.params, goal, start_n)
    pos = start_n
    path = [start_n]
    obstacles: dict[str, int] = {}

    def done(status: MissionStatus, reason: str, measured: Vec3) -> Outcome:
        return Outcome(status, reason, len(path) - 1, path, {
            "cost_evaluations": planner.cost_evaluations,
            "final_pos_n": list(measured),
            "goal_error_m": math.dist(measured, goal),
            "obstacle_steps": obstacles,
        }, loop=LOOP)

    k = 0
    measured = start_n
    for k in range(setup.max_steps + 1):
        reading = port.reading(v)
        measured = port.position_n(v)
        decision = planner.step(pos, reading)
        payload = epbha_payload(k, pos, reading, decision, planner.cost_evaluations)
        payload["measured"] = xyz(measured)
        t = port.now_s()
        port.rec.put(STEP_EPBHA, t, payload)
        port.rec.pose(t, measured)
        obstacles[decision.obstacle.value] = obstacles.get(decision.obstacle.value, 0) + 1
        port.say(f"step {k:4d} at ({measured[0]:+.2f}, {measured[1]:+.2f}, alt "
                 f"{-measured[2]:.2f}) {decision.status.value:8s} {decision.reason.value} "
                 f"[{decision.obstacle.value}]")
        if decision.status is Status.REACHED:
            err = math.dist(measured, goal)
            if err <= spec.goal_tolerance_m:
                return done(MissionStatus.REACHED, "goal reached", measured)
            return done(MissionStatus.FAILED, f"stopped {err:.2f} m from the goal "
                        f"(tolerance {spec.goal_tolerance_m:g} m)", measured)
        if decision.status is Status.DEADLOCK:
            return done(MissionStatus.FAILED, decision.reason.value, measured)
        if gone := port.check():
            return done(MissionStatus.FAILED, gone_reason(gone), measured)
        if port.over_budget():
            return done(MissionStatus.FAILED, f"mission time {spec.max_duration_s:g} s spent "
                        f"after {k} steps", measured)
        if k == setup.max_steps:
            break  # a move the planner would never see the end of
        pos = port.go({v: decision.next_pos_n})[v]
        path.append(decision.next_pos_n)
    return done(MissionStatus.FAILED, f"no goal within {setup.max_steps} steps", measured)
