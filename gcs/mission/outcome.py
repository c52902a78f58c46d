"""How a planner loop ended, and the mission report made from it in either world."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

from gcs.mission.report import MissionReport, MissionStatus, RunMode
from gcs.mission.spec import MissionSpec
from planners.geometry import Vec3


@dataclass(slots=True)
class Outcome:
    """How a planner's part of a mission ended, and what it measured.

    `loop` names the planner loop that produced it: the kinematic world and the vehicles run
    the same one, and the report says which (a test holds both runs to it).
    """

    status: MissionStatus
    reason: str
    steps: int
    path_n: list[Vec3]
    metrics: dict[str, Any] = field(default_factory=dict)
    products: Any = None
    loop: str = ""


def path_length_m(path: list[Vec3]) -> float:
    """Length of a polyline in metres."""
    return sum(math.dist(a, b) for a, b in itertools.pairwise(path))


def gone_reason(gone: dict[int, str]) -> str:
    """One line for the vehicles taken off the mission."""
    return "; ".join(f"vehicle {v}: {why}" for v, why in sorted(gone.items()))


def mission_report(spec: MissionSpec, mode: RunMode, outcome: Outcome, *, collisions: int,
                   books: dict[str, Any], duration_s: float, wall_s: float,
                   recording: str | None, path_length: float | None = None) -> MissionReport:
    """The report of a finished loop: its metrics, then the backend's safety `books`.

    A run that reached its goal but collided on the way has failed, in either world.
    """
    status, reason = outcome.status, outcome.reason
    if collisions and status is MissionStatus.REACHED:
        status, reason = MissionStatus.FAILED, f"{reason}, but {collisions} collisions"
    metrics = {**outcome.metrics, **books}
    if outcome.loop:
        metrics["planner_loop"] = outcome.loop
    return MissionReport(
        mission=spec.name, planner=spec.planner.value, mode=mode, status=status, reason=reason,
        collisions=collisions,
        path_length_m=path_length if path_length is not None else path_length_m(outcome.path_n),
        duration_s=duration_s, wall_s=wall_s, steps=outcome.steps, recording=recording,
        metrics=metrics)
