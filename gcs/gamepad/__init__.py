"""Gamepad teleop: SDL2 pads mapped by a TOML file onto the pilot's intents.

- `mapping`: the TOML format, the bundled entries (`pads.toml`) and their checks;
- `core`: pure — shaped sticks and button presses to `gcs.pilot.intents`, and the unplug policy;
- `sdl_pad`: SDL at the edge (pysdl2 + pysdl2-dll), hot-plug included;
- `driver`: the pad as the teleop app polls it.
"""

from gcs.gamepad.core import GamepadPilot, PadPhase, PadSample, PadStatus, VehicleState, shape
from gcs.gamepad.driver import Gamepad, PadSource
from gcs.gamepad.mapping import MappingSet, PadMapping, PadSettings, load_mappings

__all__ = [
    "Gamepad", "GamepadPilot", "MappingSet", "PadMapping", "PadPhase", "PadSample",
    "PadSettings", "PadSource", "PadStatus", "VehicleState", "load_mappings", "shape",
]
