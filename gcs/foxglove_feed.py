"""What Foxglove's 3D panel needs to show a flight move, derived from what the station records.

`FoxgloveFeed` stands where the station expects its recorder: every `put` and `put_raw` goes on
unchanged to the recorder and to the live view (either may be absent; with both, the live view
takes the recorder's JSON from its writer thread instead of encoding it again), and from the
station's
own topics it derives, at most `rate_hz` times a second of station time (files stay small, and a
25 ms loop pays for one small dict now and then, not per record):

- `/gcs/pose/estimate`: `foxglove.FrameTransform` ned → `vehicle<N>_estimate`, the station's
  estimate: its altitude, x/y from motion capture when there is one (else 0), the attitude;
- `/gcs/pose/mocap`: `foxglove.FrameTransform` ned → `vehicle<N>_mocap`, motion capture's pose;
- `/gcs/scene/setpoint`: `foxglove.SceneUpdate`, a sphere at the held set point (a short
  lifetime, so it disappears when the station stops holding);
- `/gcs/scene/world`: `foxglove.SceneUpdate`, the world file's room and boxes, and `/tf`'s
  world → ned again, every few seconds (a seek or a late client still finds them);
- `/log`: each station event (`/gcs/events`) again as a `foxglove.Log` line, for the Log panel.

Everything is built on the loop's thread as plain dicts; JSON and disk happen in the recorder's
and the live view's own threads.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from firmware_link.records import Attitude, MocapPose
from gcs import topics
from gcs.errors import RuntimeFault, UsageError
from gcs.estimation import AltEstimate
from gcs.supervisor import Intent, IntentKind
from logs.errors import RecordingError
from logs.foxglove import (
    LogLevel,
    SceneBox,
    foxglove_log,
    foxglove_scene,
    foxglove_scene_from_boxes,
    foxglove_transform,
    ned_display_transform,
    scene_entity,
    scene_sphere,
)
from logs.topics import LOG_TOPIC, TF_TOPIC
from worldfile import WorldFileError, load_world_file

if TYPE_CHECKING:  # the recorder and the live view are opened only when asked for
    from logs.live import LiveView
    from logs.recorder import Recorder

POSE_ESTIMATE = "/gcs/pose/estimate"
POSE_MOCAP = "/gcs/pose/mocap"
SCENE_SETPOINT = "/gcs/scene/setpoint"
SCENE_WORLD = "/gcs/scene/world"
FEED_TOPICS = (POSE_ESTIMATE, POSE_MOCAP, SCENE_SETPOINT, SCENE_WORLD)
DEFAULT_RATE_HZ = 15.0
WORLD_EVERY_S = 5.0
SETPOINT_COLOR = (0.1, 0.8, 0.2, 0.7)
SETPOINT_DIAMETER_M = 0.12
ROOM_COLOR = (0.8, 0.8, 0.9, 0.08)  # the room as a faint shell, as missions draw it
# the bundled SITL's world when it is given none (sitl.world.default_world, as a file)
DEFAULT_WORLD = Path(__file__).resolve().parents[1] / "worlds" / "empty_room.toml"


def _log_level(level: Any) -> LogLevel:
    try:
        return LogLevel(int(level))
    except (TypeError, ValueError):
        return LogLevel.UNKNOWN


def open_live(address: str) -> LiveView:
    """A started `logs.live.LiveView` on `[HOST:]PORT`; one line when it cannot be."""
    from logs.live import LiveView, parse_address

    try:
        host, port = parse_address(address)
    except RecordingError as exc:
        raise UsageError(str(exc)) from None
    try:
        return LiveView(host, port)
    except RecordingError as exc:  # busy port, unknown host
        raise RuntimeFault(str(exc)) from None


def world_boxes(path: Path | None) -> list[SceneBox]:
    """The world file's room and boxes for the 3D view (none without a file)."""
    if path is None or not Path(path).is_file():
        return []
    try:
        world = load_world_file(Path(path))
    except WorldFileError as exc:
        raise UsageError(str(exc)) from None
    return [SceneBox(world.room_min_n, world.room_max_n, ROOM_COLOR, id="room")] + [
        SceneBox(b.min_n, b.max_n, id=b.name) for b in world.boxes]


def quat_from_euler(roll_rad: float, pitch_rad: float, yaw_rad: float) -> tuple[float, ...]:
    """Body → NED quaternion (w, x, y, z) of ZYX Euler angles, as MAVLink's ATTITUDE gives."""
    cr, sr = math.cos(roll_rad / 2), math.sin(roll_rad / 2)
    cp, sp = math.cos(pitch_rad / 2), math.sin(pitch_rad / 2)
    cy, sy = math.cos(yaw_rad / 2), math.sin(yaw_rad / 2)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


class FoxgloveFeed:
    """The station's recorder, plus the 3D panel's topics (see the module docstring)."""

    def __init__(self, recorder: Recorder | None, live: LiveView | None = None, *, sysid: int = 1,
                 boxes: Sequence[SceneBox] = (), rate_hz: float = DEFAULT_RATE_HZ,
                 live_prefix: str = "") -> None:
        if not rate_hz > 0:
            raise ValueError(f"rate_hz must be > 0, got {rate_hz!r}")
        self.recorder = recorder
        self.live = live
        self.sysid = sysid
        self.estimate_frame = f"vehicle{sysid}_estimate"
        self.mocap_frame = f"vehicle{sysid}_mocap"
        # several vehicles share one live view: their station topics are told apart there
        self.live_prefix = live_prefix
        # with a recording the live view is fed the recorder's own JSON (one encoding, one
        # Python worker competing with the loop for the GIL); without one it encodes itself
        self._live_direct = live if recorder is None else None
        if recorder is not None and live is not None:
            recorder.add_tap(self._tap)
        self._period_s = 1.0 / rate_hz
        self._world = foxglove_scene_from_boxes(boxes, entity_id="world") if boxes else None
        self._next_world_s = -math.inf
        self._next_estimate_s = -math.inf
        self._next_mocap_s = -math.inf
        self._next_setpoint_s = -math.inf
        self._attitude: Attitude | None = None
        self._mocap: MocapPose | None = None
        self._alt_setpoint_m: float | None = None
        self._position_sp: tuple[float, float] | None = None

    # The recorder's interface (the station's loop thread).

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        """Forward one record; update the 3D view from the station's own topics."""
        self._out(topic, t_s, payload)
        if topic == topics.ESTIMATE:
            self._on_estimate(t_s, payload)
        elif topic == topics.MOCAP_POSE and isinstance(payload, MocapPose):
            self._mocap = payload
            if t_s >= self._next_mocap_s:
                self._next_mocap_s = self._next(self._next_mocap_s, t_s)
                self._out(POSE_MOCAP, t_s, foxglove_transform(
                    "ned", self.mocap_frame, payload.pos_n, payload.q_nb))
        elif topic == topics.ATTITUDE and isinstance(payload, Attitude):
            self._attitude = payload
        elif topic == topics.ALT_CONTROLLER:
            self._alt_setpoint_m = float(payload.setpoint_m)
        elif topic == topics.INTENT and isinstance(payload, Intent):
            self._on_intent(payload)
        elif topic == topics.EVENTS and hasattr(payload, "text"):
            self._out(LOG_TOPIC, t_s, foxglove_log(_log_level(payload.level), payload.text,
                                                    f"vehicle{self.sysid}"))

    @property
    def path(self) -> Path | None:
        """The recording's file (None when only live)."""
        return self.recorder.path if self.recorder is not None else None

    def put_raw(self, direction: str, t_s: float, data: bytes) -> None:
        """Forward one raw MAVLink frame."""
        if self.recorder is not None:
            self.recorder.put_raw(direction, t_s, data)
        if self._live_direct is not None:
            self._live_direct.put_raw(direction, t_s, data)

    def event(self, t_s: float, level: LogLevel | int, text: str) -> None:
        """Forward a human-readable event ("/log")."""
        if self.recorder is not None:
            self.recorder.event(t_s, level, text)
        if self._live_direct is not None:
            self._live_direct.event(t_s, level, text)

    # Derived topics.

    def _live_topic(self, topic: str) -> str:
        # mission topics already name their vehicle (/v3/mission/pose)
        if not self.live_prefix or topic.startswith(("/mission", "/v")):
            return topic
        return self.live_prefix + topic

    def _tap(self, topic: str, schema_name: str, schema: Any, log_ns: int, data: bytes) -> None:
        # the recorder's writer thread; tapped only with a live view (see __init__)
        assert self.live is not None
        self.live.publish(self._live_topic(topic), schema_name, schema, log_ns, data)

    def _out(self, topic: str, t_s: float, payload: Any) -> None:
        if self.recorder is not None:
            self.recorder.put(topic, t_s, payload)
        if self._live_direct is not None:
            self._live_direct.put(self._live_topic(topic), t_s, payload)

    def _on_intent(self, intent: Intent) -> None:
        if intent.kind is IntentKind.POSITION:
            self._position_sp = (intent.north_m, intent.east_m)
        elif intent.kind in (IntentKind.POSITION_OFF, IntentKind.ALT_HOLD_OFF, IntentKind.KILL,
                             IntentKind.QUIT):
            self._position_sp = None
        if intent.kind in (IntentKind.ALT_HOLD_OFF, IntentKind.KILL, IntentKind.QUIT):
            self._alt_setpoint_m = None

    def _next(self, due_s: float, t_s: float) -> float:
        # on a grid of the period, so a 40 Hz source gives 15 Hz on average, not 40/3; after a
        # gap (or at the start) the grid restarts at the message
        nxt = due_s + self._period_s
        return nxt if nxt > t_s else t_s + self._period_s

    def _xy(self) -> tuple[float, float]:
        m = self._mocap
        return (m.pos_n[0], m.pos_n[1]) if m is not None else (0.0, 0.0)

    def _on_estimate(self, t_s: float, est: AltEstimate) -> None:
        if t_s >= self._next_world_s:
            self._next_world_s = t_s + WORLD_EVERY_S
            self._out(TF_TOPIC, t_s, ned_display_transform())
            if self._world is not None:
                self._out(SCENE_WORLD, t_s, self._world)
        if t_s >= self._next_estimate_s:
            self._next_estimate_s = self._next(self._next_estimate_s, t_s)
            alt_m = est.alt_m
            if math.isfinite(alt_m):
                att = self._attitude
                q = (quat_from_euler(att.roll_rad, att.pitch_rad, att.yaw_rad)
                     if att is not None else (1.0, 0.0, 0.0, 0.0))
                x, y = self._xy()
                self._out(POSE_ESTIMATE, t_s,
                          foxglove_transform("ned", self.estimate_frame, (x, y, -alt_m), q))
        sp = self._alt_setpoint_m
        if sp is not None and math.isfinite(sp) and t_s >= self._next_setpoint_s:
            self._next_setpoint_s = self._next(self._next_setpoint_s, t_s)
            x, y = self._position_sp if self._position_sp is not None else self._xy()
            sphere = scene_sphere((x, y, -sp), SETPOINT_DIAMETER_M, SETPOINT_COLOR)
            entity = scene_entity(f"vehicle{self.sysid}_setpoint", spheres=[sphere],
                                  lifetime_s=3 * self._period_s)
            self._out(SCENE_SETPOINT, t_s, foxglove_scene([entity]))
