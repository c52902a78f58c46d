"""The one place a mission's planner kind picks its loop, in the kinematic world and on vehicles.

Both backends hand over their vehicles where they hover (`starts_n`, the lead vehicle first)
and, for a radiation mission the run may score, the true field; the loop is the same either way.
"""

from __future__ import annotations

from typing import Protocol

from gcs.mission.loop_epbha import fly_epbha
from gcs.mission.loop_flock import fly_flock
from gcs.mission.loop_radiation import fly_radiation
from gcs.mission.outcome import Outcome
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.port import DetectorPort, ObstaclePort
from gcs.mission.spec import PlannerKind
from planners.geometry import Vec3
from planners.radiation.field import RadiationField


class PlannerPort(ObstaclePort, DetectorPort, Protocol):
    """A port that can fly any of the planners: IR cones and a detector."""


def fly_planner(port: PlannerPort, setup: PlannerSetup, starts_n: dict[int, Vec3],
                truth: RadiationField | None) -> Outcome:
    """Fly the mission's planner loop from where its vehicles hover."""
    kind = port.spec.planner
    first = starts_n[port.vehicles()[0]]
    if kind is PlannerKind.EPBHA:
        return fly_epbha(port, setup, first)
    if kind is PlannerKind.FLOCKING:
        return fly_flock(port, setup, starts_n)
    return fly_radiation(port, setup, first, truth)
