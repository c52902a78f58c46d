"""Gamepad mappings: which axis and button does what, read from TOML and checked on load.

The bundled `pads.toml` holds entries for the common pads; a user's file (`--gamepad-map`) is
read first, so its entries win and its `[defaults]` override the bundled ones. Every mistake a
user can make in a file (an unknown axis or button name, a bad number, a missing role) is one
`UsageError` line naming the file, the key and what is expected. Whether a raw button index
exists on the pad is known only once a pad is open: `check_against` says so in the same form.

No SDL here: names are checked against SDL's own GameController strings, kept in this module,
so the mapping (and its tests) load without a pad or the SDL library.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from importlib import resources
from pathlib import Path
from typing import Any

from gcs.errors import UsageError
from gcs.toml_file import read_toml

AXIS_ROLES: tuple[str, ...] = ("roll", "pitch", "yaw", "throttle")
BUTTON_ROLES: tuple[str, ...] = (
    "arm", "disarm", "kill", "hold", "setpoint_up", "setpoint_down",
    "stabilize", "alt_hold", "land",
)
REQUIRED_BUTTONS = frozenset({"kill"})  # a pad that flies must be able to stop the motors

# SDL_GameControllerGetStringForAxis / ...ForButton, SDL 2.0.14+
CONTROLLER_AXES = frozenset({"leftx", "lefty", "rightx", "righty", "lefttrigger", "righttrigger"})
CONTROLLER_BUTTONS = frozenset({
    "a", "b", "x", "y", "back", "guide", "start", "leftstick", "rightstick", "leftshoulder",
    "rightshoulder", "dpup", "dpdown", "dpleft", "dpright", "misc1", "paddle1", "paddle2",
    "paddle3", "paddle4", "touchpad",
})
# SDL_GameControllerType, as the lower-case word after SDL_CONTROLLER_TYPE_
CONTROLLER_TYPES = frozenset({
    "unknown", "xbox360", "xboxone", "ps3", "ps4", "ps5", "switchpro", "virtual",
    "amazon_luna", "google_stadia", "nvidia_shield", "joycon_left", "joycon_right", "joycon_pair",
})
THROTTLE_MODES = frozenset({"accumulate", "full"})
FALLBACK_CONTROLLER = "controller"
FALLBACK_JOYSTICK = "joystick"
MAX_RAW_INDEX = 255  # SDL reports counts in an int; no real pad comes near this
_RAW_AXIS = re.compile(r"axis(\d+)")


@dataclass(frozen=True, slots=True)
class AxisSource:
    """One physical axis: a GameController name or a raw index, maybe inverted."""

    name: str | None  # GameController axis name, or None for a raw axis
    index: int | None  # raw axis index, or None for a named one
    invert: bool = False

    def __str__(self) -> str:
        base = self.name if self.name is not None else f"axis{self.index}"
        return f"-{base}" if self.invert else base


@dataclass(frozen=True, slots=True)
class ButtonSource:
    """One physical button: a GameController name or a raw index."""

    name: str | None
    index: int | None

    def __str__(self) -> str:
        return self.name if self.name is not None else str(self.index)


@dataclass(frozen=True, slots=True)
class PadSettings:
    """How stick positions become commands (shared defaults, overridable per pad)."""

    deadzone: float = 0.08
    expo: float = 0.3
    throttle: str = "accumulate"
    throttle_rate_us_per_s: float = 400.0
    climb_rate_mps: float = 0.4
    setpoint_step_m: float = 0.1
    poll_hz: float = 50.0
    lost_land_s: float = 2.0


SETTING_KEYS: tuple[str, ...] = tuple(f.name for f in fields(PadSettings))


@dataclass(frozen=True, slots=True)
class PadMapping:
    """One entry of a mapping file, resolved."""

    key: str  # the entry's name in the file, e.g. "xbox"
    source: str  # the file it came from, for messages
    axes: Mapping[str, AxisSource]
    buttons: Mapping[str, ButtonSource]
    settings: PadSettings
    match: tuple[str, ...] = ()
    types: tuple[str, ...] = ()

    @property
    def needs_controller(self) -> bool:
        """Whether any binding uses a GameController name (the pad must be in SDL's database)."""
        return (any(a.name is not None for a in self.axes.values())
                or any(b.name is not None for b in self.buttons.values()))

    def check_against(self, pad_name: str, is_controller: bool, n_axes: int,
                      n_buttons: int) -> None:
        """Raise a one-line `UsageError` if this mapping cannot drive the pad as it is."""
        where = f"gamepad mapping '{self.key}' ({self.source})"
        if self.needs_controller and not is_controller:
            raise UsageError(f"{where} uses GameController names but '{pad_name}' is not in "
                             "SDL's controller database; map it with axisN and button indices")
        for role, a in self.axes.items():
            if a.index is not None and a.index >= n_axes:
                raise UsageError(f"{where}: axis '{role}' = axis{a.index} is out of range: "
                                 f"'{pad_name}' has {n_axes} axes (axis0..axis{n_axes - 1})")
        for role, b in self.buttons.items():
            if b.index is not None and b.index >= n_buttons:
                raise UsageError(f"{where}: button '{role}' = {b.index} is out of range: "
                                 f"'{pad_name}' has {n_buttons} buttons (0..{n_buttons - 1})")


@dataclass(frozen=True, slots=True)
class MappingSet:
    """Every entry of the user's file (first) and the bundled file, in the order they match."""

    entries: tuple[PadMapping, ...]

    def select(self, pad_name: str, controller_type: str | None) -> PadMapping:
        """The entry for a pad: by name, then by controller type, then the fallbacks.
        `controller_type` is None for a pad SDL's GameController database does not know."""
        low = pad_name.lower()
        for e in self.entries:
            if any(m.lower() in low for m in e.match):
                return e
        if controller_type is not None:
            for e in self.entries:
                if controller_type in e.types:
                    return e
        fallback = FALLBACK_CONTROLLER if controller_type is not None else FALLBACK_JOYSTICK
        for e in self.entries:
            if e.key == fallback:
                return e
        raise UsageError(f"no gamepad mapping for '{pad_name}': add an entry whose match "
                         f"names it, or a [pads.{fallback}] entry")


def parse_axis(text: object, where: str) -> AxisSource:
    """An axis binding from its TOML value, e.g. "-lefty" or "axis3"."""
    if not isinstance(text, str):
        raise UsageError(f"{where} = {text!r}: expected an axis name in quotes")
    invert = text.startswith("-")
    name = text[1:] if invert else text
    if name in CONTROLLER_AXES:
        return AxisSource(name, None, invert)
    raw = _RAW_AXIS.fullmatch(name)
    if raw is not None and int(raw.group(1)) <= MAX_RAW_INDEX:
        return AxisSource(None, int(raw.group(1)), invert)
    raise UsageError(f"{where} = {text!r} is not an axis: expected one of "
                     f"{', '.join(sorted(CONTROLLER_AXES))} or axisN, '-' in front to invert")


def parse_button(value: object, where: str) -> ButtonSource:
    """A button binding from its TOML value: a GameController name or a raw index."""
    if isinstance(value, bool):  # TOML true/false would pass as int 1/0
        raise UsageError(f"{where} = {value!r}: expected a button name or index")
    if isinstance(value, int):
        if not 0 <= value <= MAX_RAW_INDEX:
            raise UsageError(f"{where} = {value} is out of range: a button index is "
                             f"0..{MAX_RAW_INDEX}")
        return ButtonSource(None, value)
    if isinstance(value, str) and value in CONTROLLER_BUTTONS:
        return ButtonSource(value, None)
    raise UsageError(f"{where} = {value!r} is not a button: expected one of "
                     f"{', '.join(sorted(CONTROLLER_BUTTONS))} or an index")


def _settings(table: Mapping[str, Any], base: PadSettings, where: str) -> PadSettings:
    changes: dict[str, Any] = {}
    for key, value in table.items():
        if key not in SETTING_KEYS:
            raise UsageError(f"{where}: unknown key '{key}'; expected one of "
                             f"{', '.join(SETTING_KEYS)}")
        if key == "throttle":
            if value not in THROTTLE_MODES:
                raise UsageError(f"{where}: throttle = {value!r}; expected "
                                 f"{' or '.join(sorted(THROTTLE_MODES))}")
        elif isinstance(value, bool) or not isinstance(value, int | float):
            raise UsageError(f"{where}: {key} = {value!r}; expected a number")
        elif key == "deadzone" and not 0.0 <= value < 1.0:
            raise UsageError(f"{where}: deadzone = {value} is out of range (0 to below 1)")
        elif key == "expo" and not 0.0 <= value <= 1.0:
            raise UsageError(f"{where}: expo = {value} is out of range (0..1)")
        elif key not in ("deadzone", "expo") and value <= 0:
            raise UsageError(f"{where}: {key} = {value} must be positive")
        changes[key] = float(value) if key != "throttle" else value
    return replace(base, **changes)


def _strings(value: object, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise UsageError(f"{where}: expected a list of strings")
    return tuple(value)


def _entry(key: str, table: Any, source: str, defaults: PadSettings) -> PadMapping:
    where = f"{source}: [pads.{key}]"
    if not isinstance(table, dict):
        raise UsageError(f"{where}: expected a table")
    unknown = set(table) - {"match", "types", "axes", "buttons", *SETTING_KEYS}
    if unknown:
        raise UsageError(f"{where}: unknown key '{sorted(unknown)[0]}'; expected match, types, "
                         "axes, buttons or a setting")
    settings = _settings({k: v for k, v in table.items() if k in SETTING_KEYS}, defaults, where)
    types = _strings(table.get("types", []), f"{where} types")
    for t in types:
        if t not in CONTROLLER_TYPES:
            raise UsageError(f"{where} types: '{t}' is not an SDL controller type; expected "
                             f"one of {', '.join(sorted(CONTROLLER_TYPES))}")
    axes_t, buttons_t = table.get("axes", {}), table.get("buttons", {})
    if not isinstance(axes_t, dict) or not isinstance(buttons_t, dict):
        raise UsageError(f"{where}: axes and buttons must be tables")
    axes: dict[str, AxisSource] = {}
    for role, value in axes_t.items():
        if role not in AXIS_ROLES:
            raise UsageError(f"{where}.axes: '{role}' is not a stick; expected "
                             f"{', '.join(AXIS_ROLES)}")
        axes[role] = parse_axis(value, f"{where}.axes {role}")
    buttons: dict[str, ButtonSource] = {}
    for role, value in buttons_t.items():
        if role not in BUTTON_ROLES:
            raise UsageError(f"{where}.buttons: '{role}' is not a pad action; expected "
                             f"{', '.join(BUTTON_ROLES)}")
        buttons[role] = parse_button(value, f"{where}.buttons {role}")
    missing = [r for r in AXIS_ROLES if r not in axes] + sorted(REQUIRED_BUTTONS - set(buttons))
    if missing:
        raise UsageError(f"{where}: '{missing[0]}' is not mapped; every pad needs "
                         f"{', '.join(AXIS_ROLES)} and {', '.join(sorted(REQUIRED_BUTTONS))}")
    return PadMapping(key=key, source=source, axes=axes, buttons=buttons, settings=settings,
                      match=_strings(table.get("match", []), f"{where} match"), types=types)


def parse_mapping(data: Mapping[str, Any], source: str,
                  base: PadSettings = PadSettings()) -> tuple[PadSettings, list[PadMapping]]:
    """The defaults and entries of one parsed file (TOML tables as dicts)."""
    unknown = set(data) - {"defaults", "pads"}
    if unknown:
        raise UsageError(f"{source}: unknown table '{sorted(unknown)[0]}'; expected [defaults] "
                         "and [pads.NAME]")
    defaults_t = data.get("defaults", {})
    if not isinstance(defaults_t, dict):
        raise UsageError(f"{source}: [defaults] must be a table")
    defaults = _settings(defaults_t, base, f"{source}: [defaults]")
    pads = data.get("pads", {})
    if not isinstance(pads, dict):
        raise UsageError(f"{source}: [pads] must hold tables [pads.NAME]")
    return defaults, [_entry(k, t, source, defaults) for k, t in pads.items()]


def _read(path: Path) -> dict[str, Any]:
    return read_toml(path, label=f"gamepad map {path}")


def bundled_text() -> str:
    """The bundled mappings, as shipped."""
    return resources.files("gcs.gamepad").joinpath("pads.toml").read_text(encoding="utf-8")


def load_mappings(user_file: Path | None = None) -> MappingSet:
    """The user's entries (if any) ahead of the bundled ones. A user's `[defaults]` apply to
    every entry, bundled ones included."""
    bundled = tomllib.loads(bundled_text())
    source = "bundled pads.toml"
    defaults, _ = parse_mapping({"defaults": bundled.get("defaults", {})}, source)
    entries: list[PadMapping] = []
    if user_file is not None:
        defaults, entries = parse_mapping(_read(user_file), str(user_file), defaults)
    # the bundled entries are built on the user's defaults, so that one [defaults] table in the
    # user's file (say, a smaller deadzone) reaches the pads it does not list
    _, shipped = parse_mapping({**bundled, "defaults": {}}, source, defaults)
    return MappingSet(tuple(entries + shipped))
