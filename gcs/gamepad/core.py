"""The pure part of gamepad teleop: stick positions and buttons in, pilot intents out.

No SDL and no clock: each `step` gets the time, one sample of the pad (or None when it is
unplugged) and what the UI last heard from the vehicle, and returns the `gcs.pilot.intents` to
send. The supervisor still decides what is safe; this module only decides what the pilot's pad
asks for, and what it asks for when the pad goes away.

Who holds the altitude decides what the throttle stick means:
- PC altitude hold (take-off included): the stick moves the set point (a climb rate), centre
  holds;
- the vehicle's own ALT_HOLD: the stick goes through as ArduCopter reads it there, centre = hold;
- otherwise (STABILIZE): a manual throttle, "accumulate" (the stick moves a throttle that stays
  where it is put) or "full" (the stick's position is the throttle).

Unplugged: roll, pitch and yaw centre at once and the throttle stays where it was. A held
altitude (PC hold, or the vehicle's ALT_HOLD) stays held. Under a manual throttle nobody is
flying the vehicle, so after `lost_land_s` it is sent `SetMode("LAND")`, repeated until the
vehicle reports LAND. Plugged back in, the pad does nothing (but kill) until the pilot brings its
throttle to neutral — minimum, or meeting the throttle the station holds, or centre when the
altitude is held — and presses a button: no jump when control comes back.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from firmware_link.pwm import PWM_MAX_US, PWM_MID_US, PWM_MIN_US
from gcs.gamepad.mapping import PadSettings
from gcs.pilot import intents

THROTTLE_MIN_US = PWM_MIN_US
THROTTLE_MID_US = PWM_MID_US
THROTTLE_MAX_US = PWM_MAX_US
THROTTLE_SPAN_US = 500
PICKUP_BAND_US = 40  # how close the pad's throttle must come to the one the station holds
LAND_RESEND_S = 1.0  # a SET_MODE can be lost on the link; ask again until LAND is seen
MAX_DT_S = 0.2  # a UI stall must not turn into one big throttle or set-point jump
MANUAL_THROTTLE_MODES = frozenset({"STABILIZE", "ACRO", ""})  # "": not heard yet
MODE_BUTTONS = {"stabilize": "STABILIZE", "alt_hold": "ALT_HOLD", "land": "LAND"}


class PadPhase(enum.Enum):
    """Whether the pad has the sticks."""

    ENGAGED = "engaged"
    WAITING = "waiting"  # connected, not yet given the sticks
    UNPLUGGED = "unplugged"


@dataclass(frozen=True, slots=True)
class PadSample:
    """One reading of the pad: axes by role in -1..1 (signs applied), roles held down."""

    axes: Mapping[str, float]
    buttons: frozenset[str] = frozenset()


@dataclass(frozen=True, slots=True)
class VehicleState:
    """What the UI last heard: enough to know who holds the altitude."""

    armed: bool = False
    hold_on: bool = False  # PC altitude hold, take-off included
    mode: str = ""
    throttle_us: int | None = None  # the throttle the station sent last


@dataclass(frozen=True, slots=True)
class PadStatus:
    """For the screen: the phase, the shaped sticks, the throttle sent and a note."""

    phase: PadPhase = PadPhase.UNPLUGGED
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    throttle_axis: float = 0.0
    throttle_us: int = THROTTLE_MIN_US
    note: str = ""
    buttons: frozenset[str] = frozenset()  # roles held down


def shape(value: float, deadzone: float, expo: float) -> float:
    """Deadzone then expo: centre reads 0, full travel reads ±1, fine control near centre."""
    v = max(-1.0, min(1.0, value))
    mag = abs(v)
    if mag <= deadzone:
        return 0.0
    r = (mag - deadzone) / (1.0 - deadzone)  # no step at the deadzone's edge
    r = (1.0 - expo) * r + expo * r**3
    return math.copysign(r, v)


@dataclass(slots=True)
class GamepadPilot:
    """Turns pad samples into intents; one per pad, stepped at the poll rate."""

    settings: PadSettings = field(default_factory=PadSettings)
    phase: PadPhase = PadPhase.UNPLUGGED
    status: PadStatus = field(default_factory=PadStatus)
    _last_t_s: float | None = None
    _prev_buttons: frozenset[str] = frozenset()
    _accum_us: float = THROTTLE_MIN_US  # the accumulate mode's throttle
    _sent_us: int = THROTTLE_MIN_US  # the throttle last sent (what the station now holds)
    _started: bool = False
    _hold_was_on: bool = False
    _unmanned_since_s: float | None = None  # pad not in control under a manual throttle
    _land_sent_s: float | None = None

    def step(self, t_s: float, sample: PadSample | None,
             vehicle: VehicleState) -> list[intents.Intent]:
        """The intents for this poll."""
        dt = 0.0 if self._last_t_s is None else max(0.0, min(MAX_DT_S, t_s - self._last_t_s))
        self._last_t_s = t_s
        if not vehicle.armed:
            self._accum_us = THROTTLE_MIN_US  # the vehicle arms only with throttle at minimum
        if sample is None:
            return self._unplugged(t_s, vehicle)
        s = self.settings
        roll, pitch, yaw = (shape(sample.axes.get(a, 0.0), s.deadzone, s.expo)
                            for a in ("roll", "pitch", "yaw"))
        raw_thr = max(-1.0, min(1.0, sample.axes.get("throttle", 0.0)))
        thr_axis = shape(raw_thr, s.deadzone, s.expo)
        pressed = sample.buttons - self._prev_buttons
        self._prev_buttons = sample.buttons
        out: list[intents.Intent] = []
        if self.phase is PadPhase.UNPLUGGED:
            self.phase = PadPhase.WAITING
            self._accum_us = self._sent_us  # pick up from the throttle the station holds
        held_altitude = vehicle.hold_on or vehicle.mode == "ALT_HOLD"
        if (self._hold_was_on and not vehicle.hold_on and vehicle.armed
                and vehicle.mode == "STABILIZE" and vehicle.throttle_us is not None):
            # PC hold let go in STABILIZE: the supervisor holds the hold's last throttle until
            # the pilot's meets it; an accumulated throttle starts there, so the pad has the
            # vehicle at once instead of after a second of pushing up to it
            self._accum_us = vehicle.throttle_us
        self._hold_was_on = vehicle.hold_on
        if not vehicle.hold_on and vehicle.mode != "ALT_HOLD" and s.throttle == "accumulate":
            self._accum_us = max(THROTTLE_MIN_US, min(THROTTLE_MAX_US, self._accum_us
                                 + thr_axis * s.throttle_rate_us_per_s * dt))
        manual_us = self._manual_us(raw_thr)
        if self.phase is PadPhase.WAITING:
            if "kill" in pressed:  # kill works whoever has the sticks
                out.append(intents.Kill())
                self._accum_us = self._sent_us = THROTTLE_MIN_US
            neutral = (thr_axis == 0.0 if held_altitude
                       else manual_us <= THROTTLE_MIN_US + PICKUP_BAND_US
                       or abs(manual_us - self._sent_us) <= PICKUP_BAND_US)
            # the first pad of a session needs no button: starting with --gamepad asked for it
            if neutral and (pressed - {"kill"} or not self._started):
                self.phase = PadPhase.ENGAGED
                self._unmanned_since_s = self._land_sent_s = None
                pressed = frozenset()  # the button that gave the pad the sticks does nothing else
            else:
                self._started = True
                out += self._unmanned(t_s, vehicle)
                note = ("throttle ok: press a button" if neutral
                        else "throttle to centre, then a button" if held_altitude
                        else "throttle down, then a button")
                self._show(roll, pitch, yaw, thr_axis, note, sample.buttons)
                return out
        self._started = True
        out += self._buttons(pressed, vehicle)
        if vehicle.hold_on:
            climb = thr_axis * s.climb_rate_mps * dt
            if climb:
                out.append(intents.SetpointStep(climb))
            throttle_us = self._sent_us  # ignored under PC hold; kept for when it ends
        elif vehicle.mode == "ALT_HOLD":
            throttle_us = round(THROTTLE_MID_US + thr_axis * THROTTLE_SPAN_US)
        else:
            throttle_us = manual_us
        if "kill" in pressed:
            throttle_us = THROTTLE_MIN_US
            self._accum_us = THROTTLE_MIN_US
        self._sent_us = throttle_us
        out.append(intents.Sticks(roll=roll, pitch=pitch, yaw=yaw, throttle_us=throttle_us))
        self._show(roll, pitch, yaw, thr_axis, "", sample.buttons)
        return out

    # ------------------------------------------------------------------ helpers
    def _manual_us(self, raw_thr: float) -> int:
        if self.settings.throttle == "full":
            # the stick's position is the throttle: no deadzone (it would flatten the hover
            # region) and no expo (it would move the hover point)
            return round(THROTTLE_MID_US + raw_thr * THROTTLE_SPAN_US)
        return round(self._accum_us)

    def _buttons(self, pressed: frozenset[str], vehicle: VehicleState) -> list[intents.Intent]:
        out: list[intents.Intent] = []
        if "kill" in pressed:
            return [intents.Kill()]  # nothing else from the same poll
        if "arm" in pressed:
            out.append(intents.Arm())
        if "disarm" in pressed:
            out.append(intents.Disarm())
        if "hold" in pressed:
            out.append(intents.AltHold(not vehicle.hold_on))
        step = self.settings.setpoint_step_m
        if "setpoint_up" in pressed:
            out.append(intents.SetpointStep(step))
        if "setpoint_down" in pressed:
            out.append(intents.SetpointStep(-step))
        out += [intents.SetMode(mode) for role, mode in MODE_BUTTONS.items() if role in pressed]
        return out

    def _unplugged(self, t_s: float, vehicle: VehicleState) -> list[intents.Intent]:
        if self.phase is not PadPhase.UNPLUGGED:
            self.phase = PadPhase.UNPLUGGED
            self._prev_buttons = frozenset()
            if vehicle.mode == "ALT_HOLD" and not vehicle.hold_on:
                self._sent_us = THROTTLE_MID_US  # centre is "hold" in the vehicle's ALT_HOLD
        out = self._unmanned(t_s, vehicle)
        self._show(0.0, 0.0, 0.0, 0.0, "")
        return out

    def _unmanned(self, t_s: float, vehicle: VehicleState) -> list[intents.Intent]:
        """Nobody's pad has the sticks: level, throttle where it was, and LAND in time if that
        throttle is a manual one."""
        out: list[intents.Intent] = []
        manual = (vehicle.armed and not vehicle.hold_on
                  and vehicle.mode in MANUAL_THROTTLE_MODES)
        if not manual:
            self._unmanned_since_s = None  # a held altitude (or a landing) needs no pilot
            if vehicle.mode == "LAND" or not vehicle.armed:
                self._land_sent_s = None
        else:
            if self._unmanned_since_s is None:
                self._unmanned_since_s = t_s
            due = t_s - self._unmanned_since_s >= self.settings.lost_land_s
            if due and (self._land_sent_s is None or t_s - self._land_sent_s >= LAND_RESEND_S):
                out.append(intents.SetMode("LAND"))
                self._land_sent_s = t_s
                # LAND makes its own throttle; if the pilot switches back to STABILIZE the
                # supervisor waits for a stick at minimum, so hold ours there
                self._sent_us = THROTTLE_MIN_US
        out.append(intents.Sticks(roll=0.0, pitch=0.0, yaw=0.0, throttle_us=self._sent_us))
        return out

    def _show(self, roll: float, pitch: float, yaw: float, thr_axis: float, note: str,
              buttons: frozenset[str] = frozenset()) -> None:
        if self.phase is PadPhase.UNPLUGGED:
            if self._land_sent_s is not None:
                note = "unplugged: LAND commanded"
            elif self._unmanned_since_s is not None and self._last_t_s is not None:
                left = self.settings.lost_land_s - (self._last_t_s - self._unmanned_since_s)
                note = f"unplugged: LAND in {max(0.0, left):.1f} s"
            else:
                note = "unplugged: sticks centred"
        elif self._land_sent_s is not None:
            note = f"LAND commanded; {note}"
        self.status = PadStatus(phase=self.phase, roll=roll, pitch=pitch, yaw=yaw,
                                throttle_axis=thr_axis, throttle_us=self._sent_us, note=note,
                                buttons=buttons)
