"""Mission topics on an MCAP recording: the world, poses and the planner's state per step.

Every payload is a plain dict (flat numbers where Foxglove's Plot panel should find them), or a
Foxglove well-known message. A mission without a recorder (`--no-record`) writes nothing.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from logs import SceneBox, foxglove_pose, foxglove_scene_from_boxes
from planners.geometry import Box
from planners.proximity import Facing, ProximityReading

SCENE = "/mission/scene"
POSE = "/mission/pose"
STEP_EPBHA = "/mission/epbha/step"
STEP_FLOCK = "/mission/flock/step"
SAMPLE_RADIATION = "/mission/radiation/sample"
MAP_MEAN = "/mission/radiation/mean_cps"
MAP_VARIANCE = "/mission/radiation/log_variance"
CONTOUR = "/mission/radiation/contour"
SUMMARY = "/mission/summary"
PROGRESS = "/mission/progress"


def vehicle_topic(topic: str, sysid: int | None) -> str:
    """`/v3/mission/pose` for vehicle 3 of a team; the plain topic for a single vehicle."""
    return topic if sysid is None else f"/v{sysid}{topic}"


def reading_dict(reading: ProximityReading) -> dict[str, float | None]:
    """The six IR distances by facing name (None: nothing in cone and range)."""
    return {f.name.lower(): reading.get(f) for f in Facing}


def xyz(p: Sequence[float]) -> dict[str, float]:
    """A NED vector as {x, y, z}."""
    return {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])}


class MissionRecording:
    """Writes mission topics to a `logs.Recorder` (or nowhere when it is None)."""

    def __init__(self, recorder: Any | None) -> None:
        self.recorder = recorder

    @property
    def path(self) -> str | None:
        """The MCAP file, if recording."""
        return str(self.recorder.path) if self.recorder is not None else None

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        """Queue one message."""
        if self.recorder is not None:
            self.recorder.put(topic, t_s, payload)

    def scene(self, t_s: float, room: Box, boxes: Iterable[Box]) -> None:
        """The world's boxes as a foxglove.SceneUpdate (the room as a faint shell)."""
        if self.recorder is None:
            return
        items = [SceneBox(room.min_n, room.max_n, (0.8, 0.8, 0.9, 0.08), id="room")]
        items += [SceneBox(b.min_n, b.max_n, id=b.name) for b in boxes]
        self.put(SCENE, t_s, foxglove_scene_from_boxes(items))

    def pose(self, t_s: float, pos_n: Sequence[float], sysid: int | None = None) -> None:
        """A vehicle position as a foxglove.PoseInFrame."""
        if self.recorder is not None:
            self.put(vehicle_topic(POSE, sysid), t_s, foxglove_pose(pos_n))


def epbha_payload(step: int, pos_n: Sequence[float], reading: ProximityReading, decision: Any,
                  cost_evaluations: int) -> dict[str, Any]:
    """One EPBHA step: readings, the cost table, the decision and the obstacle class."""
    return {
        "step": step,
        "pos": xyz(pos_n),
        "reading": reading_dict(reading),
        "costs": [
            {"move": e.move.name.lower(), "pos": xyz(e.pos_n), "cost": e.cost, "free": e.free}
            for e in decision.costs
        ],
        "decision": {
            "next": xyz(decision.next_pos_n),
            "status": decision.status.value,
            "reason": decision.reason.value,
            "plane": decision.plane.name,
            "heading": decision.heading.name.lower() if decision.heading else None,
            "movement_options": decision.movement_options,
        },
        "obstacle": decision.obstacle.value,
        "cost_evaluations": cost_evaluations,
    }


def flock_payload(step: int, positions_n: dict[int, Any], readings: dict[int, ProximityReading],
                  out: Any) -> dict[str, Any]:
    """One flock step: every vehicle's position, reading, set position and mode."""
    return {
        "step": step,
        "phase": out.phase.value,
        "messages_sent": out.messages_sent,
        "formation_error_m": out.formation_error_m,
        "leader_avoiding": out.leader_avoiding,
        "held_by_guard": list(out.held_by_guard),
        "vehicles": {
            str(v): {
                "pos": xyz(positions_n[v]),
                "setpoint": xyz(out.setpoints_n[v]),
                "mode": out.modes[v].value,
                "role": out.roles[v].value,
                "reading": reading_dict(readings[v]),
            }
            for v in positions_n
        },
    }


def radiation_payload(step: int, pos_n: Sequence[float], counts_per_s: float,
                      decision: Any) -> dict[str, Any]:
    """One radiation sample and what the mapper asked for next."""
    return {
        "step": step,
        "x": float(pos_n[0]),
        "y": float(pos_n[1]),
        "counts_per_s": float(counts_per_s),
        "phase": decision.phase.value,
        "reason": decision.reason,
        "next_x": float(decision.next_pos_n[0]),
        "next_y": float(decision.next_pos_n[1]),
        "hotspots": len(decision.hotspots),
        "level_cps": decision.level_cps,
    }
