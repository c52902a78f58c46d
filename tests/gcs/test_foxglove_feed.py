"""FoxgloveFeed: what the 3D view gets from the station's topics (no sockets, a list recorder)."""

from __future__ import annotations

import math
from typing import Any

from firmware_link.records import Attitude, MocapPose
from gcs import topics
from gcs.foxglove_feed import (
    POSE_ESTIMATE,
    POSE_MOCAP,
    SCENE_SETPOINT,
    SCENE_WORLD,
    FoxgloveFeed,
    quat_from_euler,
)
from gcs.supervisor import Intent, IntentKind
from logs.foxglove import FoxgloveMessage, SceneBox
from logs.topics import LOG_TOPIC, TF_TOPIC


class ListRecorder:
    """Keeps what it is given, in order."""

    def __init__(self) -> None:
        self.items: list[tuple[str, float, Any]] = []
        self.raw: list[tuple[str, float, bytes]] = []

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        self.items.append((topic, t_s, payload))

    def put_raw(self, direction: str, t_s: float, data: bytes) -> None:
        self.raw.append((direction, t_s, data))

    def on(self, topic: str) -> list[tuple[float, Any]]:
        return [(t, p) for tp, t, p in self.items if tp == topic]


class Estimate:
    def __init__(self, alt_m: float) -> None:
        self.alt_m = alt_m


class AltOut:
    def __init__(self, setpoint_m: float) -> None:
        self.setpoint_m = setpoint_m


class Event:
    def __init__(self, level: int, text: str) -> None:
        self.level = level
        self.text = text


def _fly(feed: FoxgloveFeed, seconds: float, *, mocap: bool = True) -> None:
    """40 Hz estimates climbing to 1 m, mocap at 100 Hz, attitude at 40 Hz, a 1 m set point."""
    n = round(seconds * 400)
    for k in range(n):
        t = k / 400
        if mocap and k % 4 == 0:
            feed.put(topics.MOCAP_POSE, t, MocapPose(t, 1, (0.5, -0.25, -min(t, 1.0)),
                                                     (1.0, 0.0, 0.0, 0.0), 0))
        if k % 10 == 0:
            feed.put(topics.ATTITUDE, t, Attitude(t, 1, 0.0, 0.0, math.pi / 2, 0, 0, 0))
            feed.put(topics.ALT_CONTROLLER, t, AltOut(1.0))
            feed.put(topics.ESTIMATE, t, Estimate(min(t, 1.0)))


def test_everything_passes_through_and_the_pose_is_rate_limited() -> None:
    rec = ListRecorder()
    feed = FoxgloveFeed(rec, sysid=2, boxes=[SceneBox((0, 0, -1), (1, 1, 0), id="box")])
    _fly(feed, 4.0)
    assert len(rec.on(topics.ESTIMATE)) == 160 and len(rec.on(topics.MOCAP_POSE)) == 400
    est = rec.on(POSE_ESTIMATE)
    mocap = rec.on(POSE_MOCAP)
    # 15 Hz however fast the sources come (40 Hz estimate, 100 Hz mocap)
    assert 59 <= len(est) <= 61 and 59 <= len(mocap) <= 61
    last = est[-1][1].data
    assert last["parent_frame_id"] == "ned" and last["child_frame_id"] == "vehicle2_estimate"
    # x/y from motion capture, altitude from the estimate (NED z = -alt), yaw from ATTITUDE
    assert last["translation"] == {"x": 0.5, "y": -0.25, "z": -1.0}
    w, z = last["rotation"]["w"], last["rotation"]["z"]
    assert math.isclose(w, math.sqrt(0.5)) and math.isclose(z, math.sqrt(0.5))
    assert mocap[-1][1].data["child_frame_id"] == "vehicle2_mocap"
    world = rec.on(SCENE_WORLD)
    assert len(world) == 1 and world[0][1].data["entities"][0]["cubes"]
    assert len(rec.on(TF_TOPIC)) == 1  # world → ned again every 5 s
    sp = rec.on(SCENE_SETPOINT)[-1][1].data["entities"][0]
    assert sp["spheres"][0]["pose"]["position"] == {"x": 0.5, "y": -0.25, "z": -1.0}
    assert 0 < sp["lifetime"]["nsec"] <= 300_000_000  # gone soon after the hold ends


def test_without_mocap_the_estimate_stands_at_the_origin() -> None:
    rec = ListRecorder()
    _fly(FoxgloveFeed(rec), 1.0, mocap=False)
    assert rec.on(POSE_MOCAP) == []
    t, last = rec.on(POSE_ESTIMATE)[-1]
    assert last.data["translation"] == {"x": 0.0, "y": 0.0, "z": -min(t, 1.0)}
    assert rec.on(SCENE_WORLD) == []  # no world file, no boxes


def test_intents_move_and_clear_the_set_point() -> None:
    rec = ListRecorder()
    feed = FoxgloveFeed(rec)
    feed.put(topics.INTENT, 0.0, Intent(IntentKind.POSITION, north_m=2.0, east_m=1.0))
    feed.put(topics.ALT_CONTROLLER, 0.0, AltOut(0.8))
    feed.put(topics.ESTIMATE, 0.0, Estimate(0.5))
    pos = rec.on(SCENE_SETPOINT)[-1][1].data["entities"][0]["spheres"][0]["pose"]["position"]
    assert pos == {"x": 2.0, "y": 1.0, "z": -0.8}
    feed.put(topics.INTENT, 0.1, Intent(IntentKind.ALT_HOLD_OFF))
    before = len(rec.on(SCENE_SETPOINT))
    feed.put(topics.ESTIMATE, 1.0, Estimate(0.5))
    assert len(rec.on(SCENE_SETPOINT)) == before


def test_events_become_log_lines_and_raw_frames_pass() -> None:
    rec = ListRecorder()
    feed = FoxgloveFeed(rec, sysid=3)
    feed.put(topics.EVENTS, 1.0, Event(3, "link lost"))
    feed.put_raw("rx", 1.0, b"\xfe\x01")
    ((_, log),) = rec.on(LOG_TOPIC)
    assert isinstance(log, FoxgloveMessage) and log.schema_name == "foxglove.Log"
    assert (log.data["level"], log.data["message"], log.data["name"]) == (3, "link lost",
                                                                          "vehicle3")
    assert rec.raw == [("rx", 1.0, b"\xfe\x01")]


def test_quaternion_of_euler_angles() -> None:
    w, x, y, z = quat_from_euler(0.3, -0.2, 1.0)
    assert math.isclose(w * w + x * x + y * y + z * z, 1.0)
    assert quat_from_euler(math.pi, 0, 0) == (math.cos(math.pi / 2), 1.0, 0.0, 0.0)
