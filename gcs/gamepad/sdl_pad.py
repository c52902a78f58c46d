"""SDL at the edge: find a pad, open it, read it, notice it go and come back.

SDL2 comes from pysdl2 with the SDL library of pysdl2-dll; it is imported only when a pad is
asked for, so teleop without `--gamepad` never loads it. Only the joystick and GameController
subsystems start (no window, no video). SDL's own signal handlers are turned off: they would
turn the terminal's SIGINT/SIGTERM into SDL events nobody reads, and `quadgcs teleop` would not
stop. Joystick events are ignored too: `read` asks SDL for the current state instead, so there is
no event queue to fill up between polls.

A pad that is unplugged reads as None; once a device with the same GUID (or, failing that, the
same name) appears again it is reopened, with the mapping already checked against it.
"""

from __future__ import annotations

import ctypes
import os
import warnings
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any

from gcs.errors import RuntimeFault, UsageError
from gcs.gamepad.core import PadSample
from gcs.gamepad.mapping import MappingSet, PadMapping, PadSettings

AXIS_FULL = 32767.0
TRIGGERS = frozenset({"lefttrigger", "righttrigger"})
# SDL_CONTROLLER_TYPE_<X> → the name mapping files use
_TYPE_NAMES = {
    "XBOX360": "xbox360", "XBOXONE": "xboxone", "PS3": "ps3", "PS4": "ps4", "PS5": "ps5",
    "NINTENDO_SWITCH_PRO": "switchpro", "VIRTUAL": "virtual", "AMAZON_LUNA": "amazon_luna",
    "GOOGLE_STADIA": "google_stadia", "NVIDIA_SHIELD": "nvidia_shield",
    "NINTENDO_SWITCH_JOYCON_LEFT": "joycon_left", "NINTENDO_SWITCH_JOYCON_RIGHT": "joycon_right",
    "NINTENDO_SWITCH_JOYCON_PAIR": "joycon_pair", "UNKNOWN": "unknown",
}


def init_sdl() -> ModuleType:
    """Import pysdl2 and start SDL's joystick subsystems (reference-counted by SDL)."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    with warnings.catch_warnings():
        # pysdl2 announces which SDL binary it loaded; on a terminal UI that is noise
        warnings.simplefilter("ignore", UserWarning)
        try:
            import sdl2
        except ImportError as exc:  # pysdl2 missing, or no SDL library for it
            raise RuntimeFault(f"gamepad: SDL2 is not available ({exc}); "
                               "install pysdl2 and pysdl2-dll") from None
    sdl2.SDL_SetHint(sdl2.SDL_HINT_NO_SIGNAL_HANDLERS, b"1")
    sdl2.SDL_SetHint(sdl2.SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, b"1")
    if sdl2.SDL_InitSubSystem(sdl2.SDL_INIT_JOYSTICK | sdl2.SDL_INIT_GAMECONTROLLER) != 0:
        raise RuntimeFault(f"gamepad: SDL did not start: {_error(sdl2)}")
    sdl2.SDL_JoystickEventState(sdl2.SDL_IGNORE)
    sdl2.SDL_GameControllerEventState(sdl2.SDL_IGNORE)
    module: ModuleType = sdl2  # pysdl2 ships no types: an untyped module to the checker
    return module


def quit_sdl(sdl2: ModuleType) -> None:
    """Release one reference to the subsystems `init_sdl` started."""
    sdl2.SDL_QuitSubSystem(sdl2.SDL_INIT_JOYSTICK | sdl2.SDL_INIT_GAMECONTROLLER)


def _error(sdl2: ModuleType) -> str:
    return (sdl2.SDL_GetError() or b"unknown error").decode(errors="replace")


@dataclass(frozen=True, slots=True)
class PadInfo:
    """A connected device, before it is opened."""

    index: int
    name: str
    guid: str
    controller_type: str | None  # None: not in SDL's GameController database


def _guid(sdl2: ModuleType, guid: Any) -> str:
    buf = ctypes.create_string_buffer(33)
    sdl2.SDL_JoystickGetGUIDString(guid, buf, 33)
    return buf.value.decode()


def list_pads(sdl2: ModuleType) -> list[PadInfo]:
    """Every joystick SDL sees now, in device-index order."""
    sdl2.SDL_JoystickUpdate()  # picks up devices added or removed since the last call
    pads = []
    for i in range(sdl2.SDL_NumJoysticks()):
        name = (sdl2.SDL_JoystickNameForIndex(i) or b"").decode(errors="replace") or f"pad {i}"
        ctype = None
        if sdl2.SDL_IsGameController(i):
            raw = sdl2.SDL_GameControllerTypeForIndex(i)
            ctype = next((v for k, v in _TYPE_NAMES.items()
                          if getattr(sdl2, f"SDL_CONTROLLER_TYPE_{k}", None) == raw), "unknown")
        pads.append(PadInfo(i, name, _guid(sdl2, sdl2.SDL_JoystickGetDeviceGUID(i)), ctype))
    return pads


def choose(pads: list[PadInfo], selector: str | None) -> PadInfo:
    """The pad `--gamepad` names: none → the first, digits → that index, else a name match."""
    seen = ", ".join(f"{p.index}: {p.name}" for p in pads) or "none"
    if not pads:
        raise RuntimeFault("gamepad: no pad connected")
    if not selector:
        return pads[0]
    if selector.isdigit():
        for p in pads:
            if p.index == int(selector):
                return p
        raise RuntimeFault(f"gamepad: no pad at index {selector} (connected: {seen})")
    low = selector.lower()
    for p in pads:
        if low in p.name.lower():
            return p
    raise RuntimeFault(f"gamepad: no pad named like '{selector}' (connected: {seen})")


class SdlPad:
    """One gamepad through SDL, read by role through its mapping."""

    def __init__(self, selector: str | None, mappings: MappingSet,
                 poll_hz: float | None = None) -> None:
        self._sdl = init_sdl()
        self._js: Any = None
        self._gc: Any = None
        try:
            info = choose(list_pads(self._sdl), selector)
            self.mapping: PadMapping = mappings.select(info.name, info.controller_type)
            self.name = info.name
            self._guid = info.guid
            self._open(info)
        except BaseException:
            self.close()
            raise
        settings = self.mapping.settings
        self.settings: PadSettings = (replace(settings, poll_hz=poll_hz) if poll_hz
                                      else settings)
        self._sdl_axis = {r: self._sdl.SDL_GameControllerGetAxisFromString(a.name.encode())
                          for r, a in self.mapping.axes.items() if a.name is not None}
        self._sdl_button = {r: self._sdl.SDL_GameControllerGetButtonFromString(b.name.encode())
                            for r, b in self.mapping.buttons.items() if b.name is not None}

    @property
    def connected(self) -> bool:
        """Whether the pad is open and attached now."""
        return self._js is not None

    def _open(self, info: PadInfo) -> None:
        sdl2 = self._sdl
        if self.mapping.needs_controller and info.controller_type is not None:
            self._gc = sdl2.SDL_GameControllerOpen(info.index)
            self._js = sdl2.SDL_GameControllerGetJoystick(self._gc) if self._gc else None
        else:
            self._js = sdl2.SDL_JoystickOpen(info.index) or None
        if not self._js:
            self._js = self._gc = None
            raise RuntimeFault(f"gamepad: cannot open '{info.name}': {_error(sdl2)}")
        try:
            self.mapping.check_against(
                info.name, info.controller_type is not None,
                sdl2.SDL_JoystickNumAxes(self._js), sdl2.SDL_JoystickNumButtons(self._js))
        except UsageError:
            self._drop()
            raise

    def _drop(self) -> None:
        if self._gc:
            self._sdl.SDL_GameControllerClose(self._gc)
        elif self._js:
            self._sdl.SDL_JoystickClose(self._js)
        self._js = self._gc = None

    def _reopen(self) -> bool:
        pads = list_pads(self._sdl)
        again = (next((p for p in pads if p.guid == self._guid), None)
                 or next((p for p in pads if p.name == self.name), None))
        if again is None:
            return False
        try:
            self._open(again)
        except (RuntimeFault, UsageError):
            return False  # a different pad under the same name: keep waiting for ours
        return True

    def read(self) -> PadSample | None:
        """The pad's state now, by role; None while it is unplugged."""
        sdl2 = self._sdl
        if self._js is not None:
            sdl2.SDL_JoystickUpdate()
            if not sdl2.SDL_JoystickGetAttached(self._js):
                self._drop()
        if self._js is None and not self._reopen():
            return None
        axes = {role: self._axis(role) for role in self.mapping.axes}
        buttons = frozenset(role for role in self.mapping.buttons if self._button(role))
        return PadSample(axes, buttons)

    def _axis(self, role: str) -> float:
        src = self.mapping.axes[role]
        if src.name is not None:
            raw: int = self._sdl.SDL_GameControllerGetAxis(self._gc, self._sdl_axis[role])
            # SDL reads triggers 0..32767; -1 released .. +1 pressed matches a raw trigger axis
            value = 2.0 * raw / AXIS_FULL - 1.0 if src.name in TRIGGERS else raw / AXIS_FULL
        else:
            axis: int = self._sdl.SDL_JoystickGetAxis(self._js, src.index)
            value = axis / AXIS_FULL
        value = max(-1.0, min(1.0, value))
        return (-value if src.invert else value) + 0.0  # + 0.0: no "-0.00" on screen

    def _button(self, role: str) -> bool:
        src = self.mapping.buttons[role]
        if src.name is not None:
            return bool(self._sdl.SDL_GameControllerGetButton(self._gc, self._sdl_button[role]))
        return bool(self._sdl.SDL_JoystickGetButton(self._js, src.index))

    def close(self) -> None:
        """Close the pad and release SDL (safe to call twice)."""
        if self._sdl is None:
            return
        self._drop()
        quit_sdl(self._sdl)
        self._sdl = None  # type: ignore[assignment]
