"""Conformance of the SITL's failsafes with the real firmware's uplink fades.

Each fixture (`arducopter-{4.7dev,3.2.1}-uplink-fade.tlog` + `-truth.csv`, fixtures/README.md)
holds a real ArduCopter flown by the station at 1 m whose uplink died for 15 s at T0. From the
files this test reads the failsafe parameters the vehicle flew with, when the vehicle last heard
the station before T0, the last throttle it flew blind (relative to the station's mean hold
throttle), and the outcome rows: failsafe texts, mode changes, arm state, and whether it climbed
or fell (truth). It then flies the SITL (lockstep, simulated clock, in-memory MAVLink) to the
same hold on the same parameters with the simulators' RC receiver (throttle at 1000 µs) and GPS,
silences the station the same way, and asserts the same rows with times within ±0.5 s.
"""

from __future__ import annotations

import csv
import dataclasses
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from sitl.autopilot import AutopilotOptions, FlightMode, Profile
from sitl.autopilot.profile import RcInput
from sitl.simulation import Simulation
from tests.fixture_paths import FIXTURES
from tests.sitl.flight_helpers import HOVER_STICK_US, STREAM_ALL, Pilot, big_room, take_off
from tests.sitl.gcs_peer import MemoryGcs, mavlink

os.environ["MAVLINK20"] = "1"  # 4.7 fixtures are MAVLink 2; the v2 module parses v1 too
from pymavlink import mavutil

WINDOW_S = 15.0  # the fade's length
TOLERANCE_S = 0.5
HOLD_M = 1.0
MEAN_WINDOW_S = 5.0  # the station's throttle averaged over this before T0 stands for hover
FAILSAFE_PARAMS = ("FS_GCS_ENABLE", "FS_GCS_TIMEOUT", "FS_OPTIONS", "FS_THR_ENABLE", "RTL_ALT",
                   "RC_OVERRIDE_TIME")
CASES = {"4.7dev": Profile.COPTER4, "3.2.1": Profile.APM25}
RTL_ALT_DEFAULT_CM = 1500.0  # both firmwares' parameter lists (fixtures' params.txt)
CLIMB_M = 3.0  # a rise this big over the hold counts as a climb
FLOOR_M = 0.05


@dataclass
class Outcome:
    """What happened after T0 (times relative to T0)."""

    texts: list[tuple[float, str]] = field(default_factory=list)
    modes: list[tuple[float, int]] = field(default_factory=list)  # mode changes
    disarmed_s: float | None = None
    heartbeats: set[tuple[int, int, int]] = field(default_factory=set)  # mode, base, status
    hold_m: float = 0.0
    series: list[tuple[float, float]] = field(default_factory=list)  # height over the rest

    @property
    def peak_m(self) -> float:
        return max(a for _, a in self.series)

    @property
    def floor_s(self) -> float | None:
        return next((t for t, a in self.series if a < FLOOR_M), None)

    @property
    def motion(self) -> str:
        if self.floor_s is not None:
            return "fall"
        return "climb" if self.peak_m - self.hold_m > CLIMB_M else "hold"

    @property
    def climbed_s(self) -> float:
        """When the climb had covered 90 % of its height."""
        mark = self.hold_m + 0.9 * (self.peak_m - self.hold_m)
        return next(t for t, a in self.series if a >= mark)


@dataclass
class Fixture:
    """The station's side of a fade and the vehicle's answer."""

    t0: float
    params: dict[str, float]
    last_heard_s: float  # the last frame that reached the vehicle, relative to T0
    blind_offset_us: float  # the last override minus the station's mean hold throttle
    outcome: Outcome


def _t0(name: str) -> float:
    """T0 of a fade as fixtures/README.md gives it (the tlog holds what the station sent, not
    what the proxy dropped)."""
    text = (FIXTURES / "README.md").read_text(encoding="utf-8")
    m = re.search(rf"arducopter-{re.escape(name)}-uplink-fade\.tlog`.*?T0 = (?:epoch )?([0-9.]+)",
                  text, re.S)
    assert m, f"no T0 for {name} in fixtures/README.md"
    return float(m.group(1))


def _truth(path: Path, t0: float, out: Outcome) -> None:
    with path.open(encoding="utf-8") as f:
        rows = [(float(r["t_s"]) - t0, float(r["alt_m"])) for r in csv.DictReader(f)]
    before = [a for t, a in rows if -1.0 <= t < 0.0]
    out.hold_m = sum(before) / len(before)
    out.series = [(t, a) for t, a in rows if 0.0 <= t < WINDOW_S]


def read_fixture(name: str) -> Fixture:
    t0 = _t0(name)
    conn: Any = mavutil.mavlink_connection(str(FIXTURES / f"arducopter-{name}-uplink-fade.tlog"),
                                           dialect="ardupilotmega")
    params: dict[str, float] = {}
    throttle: list[tuple[float, int]] = []
    last_heard = None
    out = Outcome()
    mode = None
    while (m := conn.recv_match(blocking=False)) is not None:
        t = m._timestamp - t0
        kind = m.get_type()
        if m.get_srcSystem() == 255:
            if t < 0.0 and kind in ("HEARTBEAT", "RC_CHANNELS_OVERRIDE"):
                last_heard = t
            if t < 0.0 and kind == "RC_CHANNELS_OVERRIDE":
                throttle.append((t, m.chan3_raw))
            continue
        if m.get_srcSystem() != 1 or m.get_srcComponent() != 1:
            continue
        if kind == "PARAM_VALUE" and m.param_id in FAILSAFE_PARAMS:
            params[m.param_id] = m.param_value
        if not 0.0 <= t < WINDOW_S:
            if kind == "HEARTBEAT":
                mode = m.custom_mode
            continue
        if kind == "HEARTBEAT":
            if m.custom_mode != mode:
                out.modes.append((t, m.custom_mode))
                mode = m.custom_mode
            out.heartbeats.add((m.custom_mode, m.base_mode, m.system_status))
            if not m.base_mode & 128 and out.disarmed_s is None:
                out.disarmed_s = t
        elif kind == "STATUSTEXT" and "ailsafe" in m.text:
            out.texts.append((t, m.text))
    assert last_heard is not None and throttle
    mean = [v for t, v in throttle if t >= -MEAN_WINDOW_S]
    _truth(FIXTURES / f"arducopter-{name}-uplink-fade-truth.csv", t0, out)
    return Fixture(t0, params, last_heard, throttle[-1][1] - sum(mean) / len(mean), out)


def _tall_room() -> Any:
    """RTL climbs to 15 m: a room tall enough that the ceiling does not stop it."""
    room = big_room()
    return dataclasses.replace(room, room_min_n=(*room.room_min_n[:2], -30.0))


def _alt(gcs: MemoryGcs, msgs: list[Any]) -> tuple[float, float] | None:
    s = gcs.of_type("SIM_STATE", msgs)
    return (s[-1].alt - gcs.sim.world.origin.alt_amsl_m, s[-1].vd) if s else None


def fly_fade(profile: Profile, fx: Fixture, seed: int = 1, run_s: float = WINDOW_S) -> Outcome:
    """Fly the SITL to the fixture's hold, fade its uplink at T0, record the outcome."""
    options = AutopilotOptions(rc_input=RcInput.MIN, gps=True)
    sim = Simulation(_tall_room(), profile, 1, seed=seed, options=options)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    gcs.heartbeat()
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, STREAM_ALL, 10, 1))
    ptype = 4 if profile is Profile.APM25 else 9
    for name, value in fx.params.items():
        if name in sim.vehicle(1).params:
            gcs.send(mavlink.MAVLink_param_set_message(1, 1, name.encode(), value, ptype))
    gcs.run(3.2)
    rest = _alt(gcs, gcs.received)
    assert rest is not None
    rest_m = rest[0]
    pilot = Pilot(gcs)
    take_off(gcs, pilot, HOLD_M)
    # the station's hold: throttle from the truth it sees, until 20 s of steady hold
    sent: list[float] = []
    state = (HOLD_M, 0.0)
    for _ in range(800):
        got = _alt(gcs, pilot.fly(0.025))
        state = got or state
        alt, down = state
        us = HOVER_STICK_US + 120.0 * (HOLD_M - alt) + 90.0 * down
        pilot.sticks[2] = round(min(1700.0, max(1300.0, us)))
        sent.append(pilot.sticks[2])
    hover = sum(sent[-int(MEAN_WINDOW_S / 0.025):]) / (MEAN_WINDOW_S / 0.025)
    pilot.sticks[2] = round(hover + fx.blind_offset_us)  # the last throttle flown blind
    pilot.fly(-fx.last_heard_s)
    pilot.overrides = pilot.heartbeats = False
    ap = sim.vehicle(1).autopilot
    t0 = sim.t_s
    out = Outcome()
    out.hold_m = state[0] - rest_m
    mode = int(ap.state.mode)
    while sim.t_s - t0 < run_s:
        msgs = gcs.run(0.01)
        t = sim.t_s - t0
        if int(ap.state.mode) != mode:
            mode = int(ap.state.mode)
            out.modes.append((t, mode))
        if not ap.state.armed and out.disarmed_s is None:
            out.disarmed_s = t
        for m in msgs:
            if m.get_type() == "HEARTBEAT" and m.get_srcComponent() == 1:
                out.heartbeats.add((m.custom_mode, m.base_mode, m.system_status))
            elif m.get_type() == "STATUSTEXT" and "ailsafe" in m.text:
                out.texts.append((t, m.text))
        got = _alt(gcs, msgs)
        if got is not None:
            out.series.append((t, got[0] - rest_m))
    return out


def _times_match(real: list[tuple[float, Any]], sitl: list[tuple[float, Any]]) -> None:
    assert [x for _, x in sitl] == [x for _, x in real]
    for (tr, x), (ts, _) in zip(real, sitl, strict=True):
        assert ts == pytest.approx(tr, abs=TOLERANCE_S), f"{x}: real +{tr:.2f} s, SITL +{ts:.2f} s"


@pytest.mark.parametrize("name", sorted(CASES))
def test_uplink_fade_outcome_matches_the_real_firmware(name: str) -> None:
    fx = read_fixture(name)
    real = fx.outcome
    sitl = fly_fade(CASES[name], fx)
    _times_match(real.texts, sitl.texts)
    _times_match(real.modes, sitl.modes)
    # what the station sees: every heartbeat the real vehicle sent armed during the fade (the
    # disarm: test_copter4_disarms_after_the_fall_when_the_real_one_does)
    assert {hb for hb in real.heartbeats if hb[1] & 128} <= sitl.heartbeats
    assert sitl.motion == real.motion
    if real.motion == "fall":
        assert sitl.floor_s == pytest.approx(real.floor_s, abs=TOLERANCE_S)
    if real.motion == "climb":
        # RTL to RTL_ALT (cm above home; the real vehicle's estimate of it was ~0.9 m high)
        rtl_alt_m = fx.params.get("RTL_ALT", RTL_ALT_DEFAULT_CM) / 100.0
        for o in (real, sitl):
            assert o.peak_m == pytest.approx(rtl_alt_m, abs=1.5)
        assert sitl.climbed_s == pytest.approx(real.climbed_s, abs=TOLERANCE_S)


@pytest.mark.xfail(strict=True, reason="#32: the SITL's copter4 keeps 3.2.1's inertial nav "
                   "(INAV_TC_Z 5 s): its 16 g accelerometer clips the 4 m/s impact, so it "
                   "believes it still falls for ~4 s and its land detector and DISARM_DELAY "
                   "disarm it at +17.3 s, where the real one disarmed at +14.96 s (unclipped it "
                   "disarms at +13.45 s: 4.x's land detector also waits for its 1 Hz filtered "
                   "acceleration to settle, which the SITL's does not model)")
def test_copter4_disarms_after_the_fall_when_the_real_one_does() -> None:
    fx = read_fixture("4.7dev")
    sitl = fly_fade(Profile.COPTER4, fx, run_s=WINDOW_S + 10.0)
    assert fx.outcome.disarmed_s is not None and sitl.disarmed_s is not None
    assert sitl.disarmed_s == pytest.approx(fx.outcome.disarmed_s, abs=TOLERANCE_S)


def test_fixture_rows_are_what_the_readme_says() -> None:
    """The rows read from the files, so a misread fixture cannot pass as conformance."""
    f4 = read_fixture("4.7dev")
    assert [x for _, x in f4.outcome.texts] == ["GCS Failsafe - Continuing Pilot Control"]
    assert f4.outcome.modes == [] and f4.outcome.motion == "fall"
    # the station's --fix-failsafe read back; FS_OPTIONS was left at 4.x's default 16
    assert f4.params["FS_GCS_ENABLE"] == 5 and f4.params["FS_GCS_TIMEOUT"] == 2
    assert "FS_OPTIONS" not in f4.params
    f3 = read_fixture("3.2.1")
    assert [x for _, x in f3.outcome.modes] == [int(FlightMode.RTL)]
    assert f3.outcome.texts == [] and f3.outcome.motion == "climb"
