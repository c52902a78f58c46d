"""An SDL virtual joystick for the tests: the same SDL joystick API as a real pad.

There is no /dev/uinput here, so a kernel-level fake pad is out; `SDL_JoystickAttachVirtualEx`
makes a device that SDL lists, opens, reads and loses exactly like a plugged-in one.
"""

from __future__ import annotations

import ctypes
from typing import Any

from gcs.gamepad.sdl_pad import init_sdl, quit_sdl

XBOX360 = {"name": "Xbox 360 Controller", "vendor_id": 0x045E, "product_id": 0x028E}
F310 = {"name": "Logitech Gamepad F310", "vendor_id": 0, "product_id": 0}


class VirtualPad:
    """A virtual pad to plug, move, press and unplug."""

    def __init__(self, name: str = XBOX360["name"], *, vendor_id: int = XBOX360["vendor_id"],
                 product_id: int = XBOX360["product_id"], controller: bool = True,
                 n_axes: int = 6, n_buttons: int = 15) -> None:
        self.sdl = init_sdl()
        self.name = name
        desc = self.sdl.SDL_VirtualJoystickDesc()
        desc.version = self.sdl.SDL_VIRTUAL_JOYSTICK_DESC_VERSION
        desc.type = (self.sdl.SDL_JOYSTICK_TYPE_GAMECONTROLLER if controller
                     else self.sdl.SDL_JOYSTICK_TYPE_UNKNOWN)
        desc.naxes, desc.nbuttons, desc.nhats = n_axes, n_buttons, 0
        desc.vendor_id, desc.product_id = vendor_id, product_id
        self._name = name.encode()
        desc.name = self._name
        self._desc = desc
        self._js: Any = None
        self.plug()

    def plug(self) -> None:
        """Attach the device (again)."""
        assert self._js is None, "already plugged in"
        index = self.sdl.SDL_JoystickAttachVirtualEx(ctypes.byref(self._desc))
        assert index >= 0, self.sdl.SDL_GetError()
        self._js = self.sdl.SDL_JoystickOpen(index)
        assert self._js, self.sdl.SDL_GetError()

    def unplug(self) -> None:
        """Detach the device, as pulling its cable does."""
        instance = self.sdl.SDL_JoystickInstanceID(self._js)
        index = next(i for i in range(self.sdl.SDL_NumJoysticks())
                     if self.sdl.SDL_JoystickGetDeviceInstanceID(i) == instance)
        self.sdl.SDL_JoystickClose(self._js)
        self._js = None
        assert self.sdl.SDL_JoystickDetachVirtual(index) == 0, self.sdl.SDL_GetError()

    def _axis_index(self, axis: str | int) -> int:
        if isinstance(axis, int):
            return axis
        # SDL maps a virtual controller's axes and buttons in its enum order
        return int(self.sdl.SDL_GameControllerGetAxisFromString(axis.encode()))

    def axis(self, axis: str | int, value: float) -> None:
        """Move an axis to `value` in -1..1 (SDL's Y axes: +1 is down)."""
        raw = max(-32768, min(32767, round(value * 32767)))
        assert self.sdl.SDL_JoystickSetVirtualAxis(self._js, self._axis_index(axis), raw) == 0

    def button(self, button: str | int, down: bool) -> None:
        """Press or release a button."""
        index = (button if isinstance(button, int)
                 else int(self.sdl.SDL_GameControllerGetButtonFromString(button.encode())))
        assert self.sdl.SDL_JoystickSetVirtualButton(self._js, index, int(down)) == 0

    def centre(self) -> None:
        """Every stick to centre, triggers released, every button up."""
        for a in range(self._desc.naxes):
            self.sdl.SDL_JoystickSetVirtualAxis(self._js, a, 0)
        for b in range(self._desc.nbuttons):
            self.sdl.SDL_JoystickSetVirtualButton(self._js, b, 0)

    def close(self) -> None:
        """Unplug (if plugged) and release SDL."""
        if self._js is not None:
            self.unplug()
        quit_sdl(self.sdl)
