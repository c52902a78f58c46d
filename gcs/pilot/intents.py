"""What the pilot asks for. The UI sends intents; the loop thread carries them out."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Arm:
    """Arm the motors (the vehicle refuses unless the throttle is at minimum)."""


@dataclass(frozen=True, slots=True)
class Disarm:
    """Disarm the motors."""


@dataclass(frozen=True, slots=True)
class SetMode:
    """Change the flight mode by ArduCopter name: STABILIZE, ALT_HOLD, LAND."""

    mode: str


@dataclass(frozen=True, slots=True)
class Sticks:
    """Stick deflections -1..1 (roll right, pitch forward, yaw right) and throttle in µs."""

    roll: float
    pitch: float
    yaw: float
    throttle_us: int


@dataclass(frozen=True, slots=True)
class AltHold:
    """Engage or release altitude hold on the PC at the current altitude."""

    on: bool


@dataclass(frozen=True, slots=True)
class SetpointStep:
    """Move the altitude-hold setpoint by this much (m, positive up)."""

    delta_m: float


@dataclass(frozen=True, slots=True)
class Kill:
    """Emergency: throttle cut and disarm, no confirmation."""


@dataclass(frozen=True, slots=True)
class TogglePause:
    """Replay only: play or pause."""


@dataclass(frozen=True, slots=True)
class ScaleSpeed:
    """Replay only: multiply the playback speed."""

    factor: float


@dataclass(frozen=True, slots=True)
class Seek:
    """Replay only: jump by this many seconds (negative goes back)."""

    delta_s: float


Intent = (
    Arm | Disarm | SetMode | Sticks | AltHold | SetpointStep | Kill
    | TogglePause | ScaleSpeed | Seek
)
