"""Missions: files, the executor that connects planners to vehicles, and their metrics."""

from gcs.mission.options import RunOptions
from gcs.mission.report import MissionReport, MissionStatus, RunMode
from gcs.mission.runner import run_mission
from gcs.mission.spec import MissionSpec, PlannerKind, load_mission
from gcs.mission.world import MissionWorld, load_world

__all__ = [
    "MissionReport",
    "MissionSpec",
    "MissionStatus",
    "MissionWorld",
    "PlannerKind",
    "RunMode",
    "RunOptions",
    "load_mission",
    "load_world",
    "run_mission",
]
