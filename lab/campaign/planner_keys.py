"""A campaign's mission with a run's `[planner]` keys over the file's own."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from gcs.mission.planner_params import planner_setup
from gcs.mission.spec import MissionSpec, load_mission


def mission_with(mission_path: Path, planner: dict[str, Any]) -> MissionSpec:
    """The mission file with these [planner] keys over its own, checked as the file's would be
    (UsageError in one line)."""
    spec = load_mission(mission_path)
    if planner:
        spec = dataclasses.replace(spec, planner_params={**spec.planner_params, **planner})
    planner_setup(spec)
    return spec
