"""Mission topics on an MCAP recording: the world, poses and the planner's state per step.

Every payload is a plain dict (flat numbers where Foxglove's Plot panel should find them), or a
Foxglove well-known message. A mission without a recorder (`--no-record`) writes nothing.

For Foxglove's 3D panel each pose is also a `foxglove.FrameTransform` ned → `vehicle<N>_mission`
(`/mission/tf`, per vehicle as `/v<N>/mission/tf` in a team), and each planner step's set
positions become `/mission/setpoint` (a sphere per vehicle) and `/mission/path` (the line through
every set position so far, at most `PATH_EVERY_S` apart in mission time, so a 400-step mission
does not write 400 growing copies of its path).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from logs import SceneBox, foxglove_pose, foxglove_scene_from_boxes, foxglove_transform
from logs.foxglove import foxglove_scene, scene_entity, scene_line_strip, scene_sphere
from planners.geometry import Box, Vec3
from planners.proximity import Facing, ProximityReading

if TYPE_CHECKING:  # the planners' result types; the loops that make them import the planners
    from planners.epbha.types import Decision as EpbhaDecision
    from planners.flocking.types import FlockStep
    from planners.radiation.types import Decision as RadiationDecision

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
POSE_TF = "/mission/tf"
SETPOINT = "/mission/setpoint"
PATH = "/mission/path"
PATH_EVERY_S = 1.0
SETPOINT_COLOR = (0.1, 0.8, 0.2, 0.8)
PATH_COLOR = (1.0, 0.6, 0.1, 0.9)


def vehicle_topic(topic: str, sysid: int | None) -> str:
    """`/v3/mission/pose` for vehicle 3 of a team; the plain topic for a single vehicle."""
    return topic if sysid is None else f"/v{sysid}{topic}"


def reading_dict(reading: ProximityReading) -> dict[str, float | None]:
    """The six IR distances by facing name (None: nothing in cone and range)."""
    return {f.name.lower(): reading.get(f) for f in Facing}


def xyz(p: Sequence[float]) -> dict[str, float]:
    """A NED vector as {x, y, z}."""
    return {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])}


class TopicSink(Protocol):
    """Where mission topics go: a `logs.Recorder`, a station's `FoxgloveFeed`, a live view."""

    def put(self, topic: str, t_s: float, payload: Any) -> None: ...


@runtime_checkable
class FileSink(TopicSink, Protocol):
    """A sink that writes a file (a live view alone writes none)."""

    @property
    def path(self) -> Path | None: ...


class MissionRecording:
    """Writes mission topics to a `logs.Recorder` (or nowhere when it is None)."""

    def __init__(self, recorder: TopicSink | None) -> None:
        self.recorder = recorder
        self._paths: dict[int, list[tuple[float, float, float]]] = {}
        self._next_path_s = -math.inf
        self._last_z_n = 0.0

    @property
    def path(self) -> str | None:
        """The MCAP file, if recording."""
        path = self.recorder.path if isinstance(self.recorder, FileSink) else None
        return str(path) if path is not None else None

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        """Queue one message (a planner step also updates the set point and the path)."""
        if self.recorder is None:
            return
        self.recorder.put(topic, t_s, payload)
        if topic in (STEP_EPBHA, STEP_FLOCK, SAMPLE_RADIATION) and isinstance(payload, dict):
            self._planned(t_s, step_setpoints(topic, payload, self._last_z_n))

    def _planned(self, t_s: float, setpoints: dict[int, tuple[float, float, float]]) -> None:
        recorder = self.recorder
        if not setpoints or recorder is None:
            return
        spheres = []
        for sysid, p in setpoints.items():
            trail = self._paths.setdefault(sysid, [])
            if not trail or trail[-1] != p:
                trail.append(p)
            spheres.append(scene_entity(f"vehicle{sysid}_setpoint",
                                        spheres=[scene_sphere(p, 0.12, SETPOINT_COLOR)]))
        recorder.put(SETPOINT, t_s, foxglove_scene(spheres))
        if t_s >= self._next_path_s:
            self._next_path_s = t_s + PATH_EVERY_S
            recorder.put(PATH, t_s, foxglove_scene(
                scene_entity(f"vehicle{sysid}_path",
                             lines=[scene_line_strip(trail, 0.03, PATH_COLOR)])
                for sysid, trail in self._paths.items() if len(trail) >= 2))

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
            self._last_z_n = float(pos_n[2])
            frame = f"vehicle{1 if sysid is None else sysid}_mission"
            self.put(vehicle_topic(POSE_TF, sysid), t_s, foxglove_transform("ned", frame, pos_n))


def step_setpoints(topic: str, payload: dict[str, Any],
                   z_n: float = 0.0) -> dict[int, tuple[float, float, float]]:
    """The set positions (NED) a planner step asked for, by vehicle (1 for a single vehicle).

    A radiation step is flat x/y (the mapper flies at one height): its set point takes `z_n`,
    the height of the vehicle's last recorded pose.
    """
    if topic == STEP_EPBHA:
        n = payload["decision"]["next"]
        return {1: (n["x"], n["y"], n["z"])}
    if topic == STEP_FLOCK:
        return {int(v): (d["setpoint"]["x"], d["setpoint"]["y"], d["setpoint"]["z"])
                for v, d in payload["vehicles"].items()}
    return {1: (payload["next_x"], payload["next_y"], z_n)}


def epbha_payload(step: int, pos_n: Sequence[float], reading: ProximityReading,
                  decision: EpbhaDecision,
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


def flock_payload(step: int, positions_n: dict[int, Vec3], readings: dict[int, ProximityReading],
                  out: FlockStep) -> dict[str, Any]:
    """One flock step: every vehicle's position, reading, set position and mode."""
    return {
        "step": step,
        "phase": out.phase.value,
        "messages_sent": out.messages_sent,
        "state_reads": out.state_reads,
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
                      decision: RadiationDecision) -> dict[str, Any]:
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
