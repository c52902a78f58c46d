"""The `althold-steps` fixtures (real ArduCopter 4.7-dev and 3.2.1, fixtures/README.md) and the
same stick steps flown on the bundled SITL in lockstep, measured the same way.

The fixture station climbed to ~1.5 m in STABILIZE, switched to ALT_HOLD at 1500 µs and held each
throttle for 4 s: 1500 1550 1600 1700 1500 1450 1400 1300 1500 1900 1500 1100 1500. A step's climb
rate is the slope of the true height over its last 2 s; its hold std is the spread of the true
height about that slope over the same 2 s.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.autopilot import FlightMode, Profile
from sitl.simulation import Simulation
from sitl.world import World, default_world
from tests.fixture_paths import FIXTURES
from tests.sitl.flight_helpers import HOVER_STICK_US, Pilot, arm
from tests.sitl.gcs_peer import MemoryGcs

STEPS_US = (1500, 1550, 1600, 1700, 1500, 1450, 1400, 1300, 1500, 1900, 1500, 1100, 1500)
STEP_S = 4.0
RATE_WINDOW_S = 2.0
HOLD_ALT_M = 1.5
FIRMWARE = {Profile.COPTER4: "4.7dev", Profile.APM25: "3.2.1"}


@dataclass(frozen=True)
class StepResult:
    """One throttle step: its stick, climb rate (m/s) and hold std (cm) over its last 2 s."""

    us: int
    rate_ms: float
    std_cm: float
    start_m: float
    end_m: float


def step_results(t: np.ndarray, alt: np.ndarray, starts: list[tuple[float, int]],
                 end_s: float) -> list[StepResult]:
    """Slope and spread of the height over the last 2 s of each step."""
    out: list[StepResult] = []
    ends = [s[0] for s in starts[1:]] + [end_s] if starts else []
    for (t0, us), t1 in zip(starts, ends, strict=True):
        sel = (t >= t0) & (t < t1)
        last = sel & (t >= t1 - RATE_WINDOW_S)
        coef = np.polyfit(t[last] - t0, alt[last], 1)
        resid = alt[last] - np.polyval(coef, t[last] - t0)
        out.append(StepResult(us, float(coef[0]), float(np.std(resid) * 100.0),
                              float(alt[sel][0]), float(alt[sel][-1])))
    return out


def fixture_steps(profile: Profile) -> list[StepResult]:
    """The real firmware's steps, from its truth (`-truth.csv`) and events."""
    base = FIXTURES / f"arducopter-{FIRMWARE[profile]}-althold-steps"
    ev = json.loads(Path(f"{base}.events.json").read_text())
    with Path(f"{base}-truth.csv").open() as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t_s"]) for r in rows])
    alt = np.array([float(r["alt_m"]) for r in rows])
    starts = [(float(s[0]), int(s[1])) for s in ev["steps"]]
    return step_results(t, alt, starts, float(ev["overrides_off"]))


@dataclass(frozen=True)
class RangeSample:
    """One rangefinder report: time from the log's start, metres (RANGEFINDER) and centimetres
    (DISTANCE_SENSOR, 4.x only; -1 when absent), with the truth height at that time."""

    t_s: float
    distance_m: float
    distance_cm: int


def fixture_rangefinder(profile: Profile) -> list[RangeSample]:
    """Every RANGEFINDER the real vehicle sent in the althold-steps tlog, paired with the
    DISTANCE_SENSOR that follows it on 4.x."""
    if profile is Profile.COPTER4:
        os.environ["MAVLINK20"] = "1"
    from pymavlink import mavutil  # after MAVLINK20 is set, as pymavlink reads it on import

    path = FIXTURES / f"arducopter-{FIRMWARE[profile]}-althold-steps.tlog"
    conn = mavutil.mavlink_connection(str(path))
    out: list[RangeSample] = []
    t0: float | None = None
    while (msg := conn.recv_match(type=["RANGEFINDER", "DISTANCE_SENSOR"])) is not None:
        if msg.get_srcSystem() != 1:
            continue
        t0 = msg._timestamp if t0 is None else t0
        if msg.get_type() == "RANGEFINDER":
            out.append(RangeSample(msg._timestamp - t0, float(msg.distance), -1))
        elif msg.orientation == 25 and out and out[-1].distance_cm < 0:
            out[-1] = dataclasses.replace(out[-1], distance_cm=int(msg.current_distance))
    conn.close()
    return out


@dataclass
class SitlFlight:
    """The steps flown on the SITL: truth at every tick and what the vehicle reported."""

    steps: list[StepResult]
    t_s: np.ndarray
    alt_m: np.ndarray
    ranges: list[tuple[float, float, int]]  # (truth height, RANGEFINDER m, DISTANCE_SENSOR cm)


def _climb_in_stabilize(
    fly: Callable[[float], None], pilot: Pilot, times: list[float], alts: list[float]
) -> None:
    """The throttle a station flies to ~1.5 m in STABILIZE from the true height: a PID about
    mid stick, 20 s (the fixture stations hovered 25 s), ending steady to a millimetre."""
    integral = 0.0
    for _ in range(1000):
        alt = alts[-1] if alts else 0.0
        climb = (alts[-1] - alts[-3]) / (times[-1] - times[-3]) if len(alts) > 2 else 0.0
        err = HOLD_ALT_M - alt
        integral = min(250.0, max(-250.0, integral + 60.0 * err * 0.02))
        us = HOVER_STICK_US + 150.0 * err - 120.0 * climb + integral
        pilot.sticks[2] = round(min(1700.0, max(1300.0, us)))
        fly(0.02)


def tall_world() -> World:
    """A 40 x 40 x 14 m hall: the steps climb about 7 m over the hold (4.7 to 8.9 m)."""
    return dataclasses.replace(
        default_world(), room_min_n=(-20.0, -20.0, -14.0), room_max_n=(20.0, 20.0, 0.0)
    )


def fly_steps(
    profile: Profile, seed: int = 1, noise: bool = True, settle_s: float = 6.0,
    steps: tuple[int, ...] = STEPS_US, climb_in_stabilize: bool = False,
    world: World | None = None,
) -> SitlFlight:
    """Arm in STABILIZE, climb to ~1.5 m, ALT_HOLD at 1500 µs, then the fixture's steps.

    The climb is on the stick in ALT_HOLD, or (`climb_in_stabilize`) as the fixture stations
    flew it: on the throttle in STABILIZE, ALT_HOLD engaged at 1500 µs once steady. The two
    differ for 3.2.1's surface tracking: engaged in the hover, its sonar target is the reading
    then; after a climb in ALT_HOLD it is wherever the stick's rate left it, between two of the
    analog sonar's 6 cm steps, and the hold dithers across the step (0.4-0.5 cm), as the
    firmware's own arithmetic does. `world` replaces the tall hall (its sensors, say)."""
    sim = Simulation(world or tall_world(), profile, 1, seed=seed, noise=noise)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    gcs.heartbeat()
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 10, 1))
    gcs.run(3.2)
    rt = sim.vehicle(1)
    rest = rt.vehicle.truth.alt_m
    times: list[float] = []
    alts: list[float] = []
    ranges: list[tuple[float, float, int]] = []
    pilot = Pilot(gcs)

    def tick() -> None:
        pilot()
        times.append(sim.t_s)
        alts.append(rt.vehicle.truth.alt_m - rest)

    def fly(seconds: float) -> None:
        for m in gcs.run(seconds, tick):
            kind = m.get_type()
            if kind == "RANGEFINDER":
                ranges.append((alts[-1] if alts else 0.0, float(m.distance), -1))
            elif (kind == "DISTANCE_SENSOR" and m.orientation == 25 and ranges
                  and ranges[-1][2] < 0):  # the down one (PITCH_270), not the IR ring
                ranges[-1] = (ranges[-1][0], ranges[-1][1], int(m.current_distance))

    ack = arm(gcs, pilot)
    assert ack.result == 0, ack
    if climb_in_stabilize:
        _climb_in_stabilize(fly, pilot, times, alts)
        gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    else:
        # climb in ALT_HOLD on the stick, then centre it
        gcs.set_mode(1, int(FlightMode.ALT_HOLD))
        pilot.sticks[2] = 1700
        while not alts or alts[-1] < HOLD_ALT_M - 0.15:
            fly(0.02)
            if sim.t_s > 60.0:
                raise AssertionError("the SITL did not climb in ALT_HOLD")
    pilot.sticks[2] = 1500
    fly(settle_s)
    starts: list[tuple[float, int]] = []
    for us in steps:
        starts.append((sim.t_s, us))
        pilot.sticks[2] = us
        fly(STEP_S)
    t = np.array(times)
    alt = np.array(alts)
    return SitlFlight(step_results(t, alt, starts, sim.t_s), t, alt, ranges)
