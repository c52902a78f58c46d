"""Faults this project fixed, put back one at a time by monkeypatching the function that fixed
them (never a switch in the product), so a test and `bench/fault_search.py` can ask whether the
fault search finds them. Each bug names the property that should catch it and a search space
focused on what could trigger it (a campaign file's [faults] table would say the same).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import Any

from firmware_link.records import FlightMode
from gcs.estimation.sonar_readings import SonarReadings
from gcs.supervisor import envelope, supervisor
from gcs.supervisor.types import Action, ActionKind, IntentKind, SupervisorState
from lab.faultsearch.space import TIME, Space

S = SupervisorState


@dataclass(frozen=True, slots=True)
class KnownBug:
    """A fixed fault, how to put it back, and what should find it."""

    name: str
    prop: str  # the property its flights violate
    space: Space  # the focused search space
    patch: Callable[[Any], None]  # (pytest's monkeypatch-like setattr target) -> None
    profile: str = "apm25"


def _kill_ignored_while_lost(mp: Any) -> None:
    """The KILL intent ignored in LINK_LOST and SILENT, as any other intent there."""
    orig = supervisor.Supervisor._apply

    def _apply(self: supervisor.Supervisor, it: Any, inp: Any) -> None:
        if it.kind is IntentKind.KILL and self.state in (S.LINK_LOST, S.SILENT):
            self._ignored(it.kind, f"{it.kind.value} ignored while {self.state.value}")
            return
        orig(self, it, inp)
    mp.setattr(supervisor.Supervisor, "_apply", _apply)


def _hold_through_land(mp: Any) -> None:
    """The hold's throttle kept on while the vehicle lands in LAND (LAND ignores the stick in
    the air, but 3.2.1 disarms after it only with the stick at minimum)."""
    orig = supervisor.Supervisor._run

    def _run(self: supervisor.Supervisor, inp: Any) -> Any:
        command, heartbeat = orig(self, inp)
        if (command is not None and self.state in (S.VEHICLE, S.QUITTING)
                and inp.vehicle.mode == FlightMode.LAND):
            command = replace(command, throttle_us=self.alt_ctrl.flown_hover_stick_us())
        return command, heartbeat
    mp.setattr(supervisor.Supervisor, "_run", _run)


def _relaunch_when_back(mp: Any) -> None:
    """A vehicle heard again after a loss gets its hold back, whatever it did meanwhile."""
    orig = supervisor.Supervisor._watch_vehicle

    def _watch_vehicle(self: supervisor.Supervisor, inp: Any) -> None:
        was = self.state
        orig(self, inp)
        v = inp.vehicle
        if (was in (S.LINK_LOST, S.VEHICLE) and v.seen and v.armed
                and self._lost_at_s > -math.inf):
            self.requested_mode, self._asked_why = int(FlightMode.STABILIZE), "resuming"
            self._actions.append(Action(ActionKind.SET_MODE, int(FlightMode.STABILIZE)))
            self._go(S.TAKEOFF, "link back: take-off again")
    mp.setattr(supervisor.Supervisor, "_watch_vehicle", _watch_vehicle)


def _carpet_zero_is_floor(mp: Any) -> None:
    """A zero sonar reading near the floor read as the floor even while the vehicle climbs."""
    orig = SonarReadings._use_reading

    def _use_reading(self: Any, *args: Any) -> Any:
        self._climb_vel_mps = 0.0
        return orig(self, *args)
    mp.setattr(SonarReadings, "_use_reading", _use_reading)


def _envelope_opens_on_climb(mp: Any) -> None:
    """The blind-flight bound opened by the (estimated) climb's speed alone."""
    orig = envelope.blind_sink_limit

    def blind_sink_limit(height_m: float, climb_mps: float, above_m: float,
                         blind: envelope.BlindFlight) -> float:
        if climb_mps > 0.0:
            return math.inf
        return orig(height_m, climb_mps, above_m, blind)
    from gcs.supervisor import commands
    mp.setattr(commands, "blind_sink_limit", blind_sink_limit)


LINK = ("fade_down", "fade_up", "fade_both")
BUGS = (
    KnownBug("kill ignored while the link is lost", "kill",
             Space(kinds=("fade_down", "pilot_kill"), anchors=("landing",), max_length_s=8.0),
             _kill_ignored_while_lost, "copter4"),  # apm25 disarms a killed vehicle late anyway
    KnownBug("the hold's throttle left on through LAND", "landed",
             Space(kinds=("mode_land", "pilot_land", "fade_down"), anchors=(TIME, "hold")),
             _hold_through_land),
    KnownBug("the station relaunching a fallen vehicle when the link returns", "no_resume",
             Space(kinds=LINK, anchors=(TIME, "hold", "step")), _relaunch_when_back),
    KnownBug("carpet zeros read as the floor during take-off", "overshoot",
             Space(kinds=("sonar_dropout", "sonar_late", "imu_spike"),
                   anchors=("takeoff",)), _carpet_zero_is_floor),
    KnownBug("the blind-flight envelope opening on the climb's speed alone", "impact",
             Space(kinds=("fade_up", "fade_both", "sonar_late"), anchors=(TIME, "hold", "step")),
             _envelope_opens_on_climb),
)


class Patcher:
    """`setattr` that undoes itself (pytest's monkeypatch outside pytest)."""

    def __init__(self) -> None:
        self._undo: list[tuple[Any, str, Any]] = []

    def setattr(self, target: Any, name: str, value: Any) -> None:
        self._undo.append((target, name, getattr(target, name)))
        setattr(target, name, value)

    def undo(self) -> None:
        for target, name, value in reversed(self._undo):
            setattr(target, name, value)
        self._undo.clear()


@contextlib.contextmanager
def inserted(bug: KnownBug) -> Iterator[None]:
    """The bug back in the product for the block."""
    p = Patcher()
    bug.patch(p)
    try:
        yield
    finally:
        p.undo()
