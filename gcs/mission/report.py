"""A mission's outcome: status, reason, safety and effort numbers, and the planner's metrics."""

from __future__ import annotations

import enum
import json
import math
from dataclasses import dataclass, field
from typing import Any


class MissionStatus(enum.Enum):
    """How a mission ended."""

    REACHED = "reached"
    FAILED = "failed"
    # flown to the end and its products made, with nothing to judge them against (no truth:
    # a real floor, a world without [[sources]], or --no-truth): not a failure, not a success
    UNSCORED = "unscored"


class RunMode(enum.Enum):
    """Where the planner flew: the kinematic world (exact moves) or a vehicle over MAVLink."""

    KINEMATIC = "kinematic"
    VEHICLE = "vehicle"


def _clean(value: Any) -> Any:
    """JSON-safe: non-finite floats become None, floats rounded to 4 decimals."""
    if isinstance(value, float):
        return round(value, 4) if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    return value


@dataclass(slots=True)
class MissionReport:
    """Everything `mission run` prints at the end (and `--json` as one object)."""

    mission: str
    planner: str
    mode: RunMode
    status: MissionStatus
    reason: str
    collisions: int
    path_length_m: float
    duration_s: float  # mission time: simulated for kinematic runs, vehicle clock otherwise
    wall_s: float
    steps: int
    recording: str | None
    metrics: dict[str, Any] = field(default_factory=dict)

    @property
    def reached(self) -> bool:
        """True when the mission's goal was met."""
        return self.status is MissionStatus.REACHED

    @property
    def ok(self) -> bool:
        """True when the command should exit 0: the goal met, or an unscored run finished."""
        return self.status in (MissionStatus.REACHED, MissionStatus.UNSCORED)

    def to_dict(self) -> dict[str, Any]:
        """The JSON object: the fixed keys first, then the planner's own metrics."""
        base: dict[str, Any] = {
            "mission": self.mission,
            "planner": self.planner,
            "mode": self.mode.value,
            "status": self.status.value,
            "reason": self.reason,
            "collisions": self.collisions,
            "path_length_m": self.path_length_m,
            "duration_s": self.duration_s,
            "wall_s": self.wall_s,
            "steps": self.steps,
            "recording": self.recording,
        }
        for k, v in self.metrics.items():
            base.setdefault(k, v)
        cleaned: dict[str, Any] = _clean(base)
        return cleaned

    def to_json(self) -> str:
        """One line of JSON."""
        return json.dumps(self.to_dict())

    def summary_lines(self) -> list[str]:
        """A human-readable summary, one fact per line."""
        d = self.to_dict()
        lines = [
            f"mission {self.mission} ({self.planner}, {self.mode.value}): {self.status.value}"
            + (f" - {self.reason}" if self.reason else ""),
            f"collisions {self.collisions}, path {d['path_length_m']} m, {self.steps} steps, "
            f"mission time {d['duration_s']} s, wall {d['wall_s']} s",
        ]
        for k, v in d.items():
            if k in self.metrics and not isinstance(v, dict | list):
                lines.append(f"  {k}: {v}")
            elif k in self.metrics:
                lines.append(f"  {k}: {json.dumps(v)}")
        lines.append(f"recording: {self.recording or 'off'}")
        return lines
