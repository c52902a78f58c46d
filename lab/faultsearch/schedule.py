"""Faults as data: a fault is (kind, start, length, size), a run is `seed + schedule`.

A schedule file (TOML) lists faults; `quadgcs fly --lockstep --seed N --faults FILE` flies it,
and the same seed and file fly the same flight bit for bit:

    [[fault]]
    kind = "fade_down"     # one of KINDS below
    start = "hold+0.4"     # simulated s since the SITL started, or PHASE[+s]
    length = 3.0           # s (an event: kill, quit, land, +, a mode change: 0)
    size = 0.0             # what the kind says (a probability, m/s², V, s, m)

Phases (`PHASES`) are the moments a fault is most likely to hurt: the take-off, the hold's
start (its first second: "hold+0.0" .. "hold+1.0"), the step, the landing and the first vehicle
mode change the station saw. A phase that never comes leaves its faults out.

Every problem is one line naming the file, the key and what was expected (`ScheduleError`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gcs.errors import UsageError
from gcs.flight_plan import FlightPlan
from worldfile import read_toml


class ScheduleError(UsageError):
    """A schedule file that cannot be flown (exit code 2)."""


@dataclass(frozen=True, slots=True)
class Kind:
    """What a kind of fault is: its size's meaning and bounds, and whether it is an event."""

    what: str
    size: str = ""  # what `size` means; "" when it means nothing
    lo: float = 0.0
    hi: float = 0.0
    event: bool = False  # an instant (length ignored)


KINDS: dict[str, Kind] = {
    "fade_down": Kind("every frame vehicle to station lost"),
    "fade_up": Kind("every frame station to vehicle lost"),
    "fade_both": Kind("every frame lost both ways"),
    "loss_down": Kind("frames vehicle to station lost at random", "probability", 0.05, 0.95),
    "loss_up": Kind("frames station to vehicle lost at random", "probability", 0.05, 0.95),
    "loss_both": Kind("frames lost at random both ways", "probability", 0.05, 0.95),
    # a flipped bit fails the frame's checksum: its reader drops it (as the fault proxy's)
    "bitflip": Kind("frames with a flipped bit both ways", "probability", 0.01, 0.5),
    "stall": Kind("the whole SITL stopped, then its missed ticks at once"),
    "sonar_dropout": Kind("the sonar's echoes lost: it reads 0 (as over carpet)"),
    "sonar_stuck": Kind("the sonar repeats its last reading"),
    "sonar_late": Kind("sonar readings arrive late", "delay s", 0.05, 1.2),
    "imu_spike": Kind("accelerometer z offset", "m/s²", -20.0, 20.0),
    "imu_stall": Kind("the IMU repeats its last sample"),
    "battery_sag": Kind("the battery voltage reads low", "V", 0.2, 3.0),
    "mode_land": Kind("the vehicle enters LAND by itself (a firmware failsafe)", event=True),
    "pilot_kill": Kind("the pilot's kill switch", event=True),
    "pilot_quit": Kind("the pilot quits (land, then let go)", event=True),
    "pilot_land": Kind("the pilot asks for LAND", event=True),
    "pilot_plus": Kind("the pilot raises the setpoint", "m", 0.05, 0.5, event=True),
}
LINK_KINDS = frozenset({"fade_down", "fade_up", "fade_both", "loss_down", "loss_up", "loss_both",
                        "bitflip"})
SENSOR_KINDS = frozenset({"sonar_dropout", "sonar_stuck", "sonar_late", "imu_spike", "imu_stall",
                          "battery_sag"})
PILOT_KINDS = frozenset({"pilot_kill", "pilot_quit", "pilot_land", "pilot_plus"})
PHASES = ("takeoff", "hold", "step", "landing", "mode")
MAX_LENGTH_S = 60.0


@dataclass(frozen=True, slots=True)
class Fault:
    """One fault: `start` in simulated s, or a phase and s after it."""

    kind: str
    start_s: float
    phase: str | None = None  # None: start_s counts from the SITL's start
    length_s: float = 0.0
    size: float = 0.0

    def begins_s(self, anchors: Mapping[str, float]) -> float | None:
        """When the fault begins, once its phase has come (None before, or never)."""
        if self.phase is None:
            return self.start_s
        at = anchors.get(self.phase)
        return None if at is None else at + self.start_s

    def active(self, t_s: float, anchors: Mapping[str, float]) -> bool:
        """Whether `t_s` falls in the fault's window."""
        b = self.begins_s(anchors)
        return b is not None and b <= t_s < b + self.length_s

    @property
    def start_text(self) -> str:
        """The start as a schedule file writes it."""
        return (repr(self.start_s) if self.phase is None
                else f'"{self.phase}+{self.start_s!r}"')


@dataclass(frozen=True, slots=True)
class Schedule:
    """The faults of one run, in file order."""

    faults: tuple[Fault, ...] = ()

    def of(self, kinds: frozenset[str]) -> tuple[Fault, ...]:
        """The faults of these kinds."""
        return tuple(f for f in self.faults if f.kind in kinds)


def flight_span_s(plan: FlightPlan) -> float:
    """A generous bound on how long `fly` takes over `plan`, in simulated s from the SITL's
    start: connect and rest, arm, climb, settle, hold, step, descend and hand over."""
    climb_s = plan.alt_m / plan.climb_mps
    descend_s = (plan.alt_m + max(plan.step_m, 0.0)) / plan.descent_mps
    return (2.0 + plan.rest_s + plan.arm_timeout_s + plan.takeoff_delay_s + climb_s + 20.0
            + plan.settle_s + plan.hold_s + (plan.step_observe_s if plan.step_m else 0.0)
            + descend_s + 30.0)


def _start(where: str, raw: Any, span_s: float | None) -> tuple[float, str | None]:
    if isinstance(raw, bool):
        raise ValueError(f"{where}: expected seconds >= 0 or PHASE[+s], got {raw!r}")
    if isinstance(raw, int | float):
        t, phase = float(raw), None
    elif isinstance(raw, str):
        name, _, off = raw.partition("+")
        name = name.strip()
        if name not in PHASES:
            raise ValueError(f"{where}: expected seconds or PHASE[+s] with PHASE one of "
                             f"{', '.join(PHASES)}, got {raw!r}")
        try:
            t = float(off) if off.strip() else 0.0
        except ValueError:
            raise ValueError(f"{where}: expected PHASE+seconds, got {raw!r}") from None
        phase = name
    else:
        raise ValueError(f"{where}: expected seconds >= 0 or PHASE[+s], got {raw!r}")
    if not (math.isfinite(t) and t >= 0.0):
        raise ValueError(f"{where}: expected a start >= 0 s, got {raw!r}")
    if span_s is not None and t > span_s:
        raise ValueError(f"{where}: {raw!r} is past the flight (it ends by {span_s:.0f} s); "
                         f"expected a start <= {span_s:.0f} s")
    return t, phase


def _number(where: str, raw: Any) -> float:
    if isinstance(raw, bool) or not isinstance(raw, int | float) or not math.isfinite(raw):
        raise ValueError(f"{where}: expected a number, got {raw!r}")
    return float(raw)


def fault_from_table(where: str, t: Any, span_s: float | None = None) -> Fault:
    """One `[[fault]]` table checked; ValueError `where.key: problem` otherwise."""
    if not isinstance(t, dict):
        raise ValueError(f"{where}: expected a table with kind, start, length, size")
    for key in t:
        if key not in ("kind", "start", "length", "size"):
            raise ValueError(f"{where}.{key}: unknown key; expected kind, start, length, size")
    kind = t.get("kind")
    if kind not in KINDS:
        raise ValueError(f"{where}.kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    k = KINDS[kind]
    if "start" not in t:
        raise ValueError(f"{where}.start: missing; expected seconds or PHASE[+s]")
    start_s, phase = _start(f"{where}.start", t["start"], span_s)
    length = _number(f"{where}.length", t.get("length", 0.0))
    if length < 0.0 or length > MAX_LENGTH_S:
        raise ValueError(f"{where}.length: expected seconds in 0..{MAX_LENGTH_S:g}, got {length:g}")
    if not k.event and length == 0.0:
        raise ValueError(f"{where}.length: expected seconds > 0 for {kind}")
    size = _number(f"{where}.size", t.get("size", 0.0))
    if k.size and not k.lo <= size <= k.hi:
        raise ValueError(f"{where}.size: expected {k.size} in {k.lo:g}..{k.hi:g} for {kind}, "
                         f"got {size:g}")
    return Fault(kind, start_s, phase, length, size if k.size else 0.0)


def schedule_from_toml(data: Mapping[str, Any], label: str,
                       span_s: float | None = None) -> Schedule:
    """A parsed schedule file's content checked; ScheduleError (one line) otherwise."""
    for key in data:
        if key != "fault":
            raise ScheduleError(f"{label}: {key}: unknown key; expected [[fault]] tables")
    raw = data.get("fault", [])
    if not isinstance(raw, list):
        raise ScheduleError(f"{label}: fault: expected [[fault]] tables")
    try:
        faults = tuple(fault_from_table(f"fault[{i}]", t, span_s) for i, t in enumerate(raw))
    except ValueError as exc:
        raise ScheduleError(f"{label}: {exc}") from None
    return Schedule(faults)


def load_schedule(path: str | Path, span_s: float | None = None) -> Schedule:
    """Read and check a schedule file; ScheduleError (one line) for any problem."""
    p = Path(path)
    data = read_toml(p, label=str(p), noun="fault schedule", error=ScheduleError)
    return schedule_from_toml(data, str(p), span_s)


def dumps(schedule: Schedule, header: str = "") -> str:
    """The schedule as a file `load_schedule` reads back to the same faults."""
    lines = [f"# {h}" for h in header.splitlines()]
    for f in schedule.faults:
        lines += ["", "[[fault]]", f'kind = "{f.kind}"', f"start = {f.start_text}",
                  f"length = {f.length_s!r}", f"size = {f.size!r}"]
    return "\n".join(lines) + "\n"
