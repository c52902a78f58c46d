"""What a fault-search run saw: the SITL's truth every simulation tick, the station every station
tick, and when each fault and landing cause happened. The safety properties read only this."""

from __future__ import annotations

from dataclasses import dataclass, field

from worldfile.schema import Box


@dataclass(frozen=True, slots=True)
class TruthSample:
    """The vehicle as the simulation has it (never what the station knows)."""

    t_s: float
    alt_m: float  # height of the body's origin above the floor (up)
    vz_down_mps: float  # vertical speed, down positive
    pos_ne: tuple[float, float]
    on_ground: bool
    touching: str | None  # the box it touches, None when clear
    armed: bool
    mode: int  # the autopilot's flight mode number


@dataclass(frozen=True, slots=True)
class StationSample:
    """One station tick: its state and what it sent."""

    t_s: float
    state: str
    setpoint_m: float | None
    est_alt_m: float | None
    throttle_us: int
    link_lost: bool


@dataclass(slots=True)
class Trace:
    """A run's record (filled while it flies, read after)."""

    truth: list[TruthSample] = field(default_factory=list)
    station: list[StationSample] = field(default_factory=list)
    events: list[tuple[float, str]] = field(default_factory=list)  # (t, fault kind) as done
    anchors: dict[str, float] = field(default_factory=dict)  # phase -> when it began
    boxes: tuple[Box, ...] = ()
    body_radius_m: float = 0.25
    gear_m: float = 0.0  # height of the body's origin above the floor at rest
    flight_end_s: float = 0.0  # when `fly` returned (or failed)
    exit_ok: bool = False  # fly's verdict: the flight went as commanded
    exit_reason: str = ""
    throttle_min_us: int = 1000

    def event_times(self, kind: str) -> list[float]:
        """When faults of `kind` were done (events: kills, quits, mode changes)."""
        return [t for t, k in self.events if k == kind]
