"""Flight recording to MCAP, reading, recovery, replay, export and plots."""

from logs.encoding import from_jsonable, to_jsonable, vector
from logs.errors import RecordingError
from logs.flight_file import Direction, files_metadata
from logs.foxglove import (
    FoxgloveMessage,
    LogLevel,
    SceneBox,
    foxglove_grid,
    foxglove_log,
    foxglove_pose,
    foxglove_scene_from_boxes,
    foxglove_transform,
    foxglove_vehicle_transform,
)
from logs.reader import Recording, open_recording
from logs.recorder import Recorder, RecorderStats

__all__ = [
    "Direction",
    "FoxgloveMessage",
    "LogLevel",
    "Recorder",
    "RecorderStats",
    "Recording",
    "RecordingError",
    "SceneBox",
    "files_metadata",
    "foxglove_grid",
    "foxglove_log",
    "foxglove_pose",
    "foxglove_scene_from_boxes",
    "foxglove_transform",
    "foxglove_vehicle_transform",
    "from_jsonable",
    "open_recording",
    "to_jsonable",
    "vector",
]
