"""#32's climb-rate hold on the bundled SITL, in lockstep: the station flies the firmware's
ALT_HOLD by climb rate, and what the vehicle does when the station stops, is killed, goes
blind or deaf, or when the vehicle changes mode by itself.

Every vehicle has a receiver at minimum (the fixtures' SITLs had one) and no GPS; the station
runs the pre-flight's fix (`--fix-failsafe`: on 4.x FS_OPTIONS 0, FS_GCS_ENABLE 5,
FS_GCS_TIMEOUT 2). Heights, vertical speeds, arming and modes are the simulation's own truth,
read only to judge. The issue's bounds for a fade: no rise over 0.3 m above the hold, no
touch-down faster than 1.0 m/s, disarmed within 20 s.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from gcs.config import HoldMode, StationConfig
from gcs.control.attitude import yaw_from_quat
from gcs.control.position_controller import PositionSetpoint
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from gcs.supervisor import SupervisorState
from sitl.autopilot import AutopilotOptions, FlightMode
from sitl.autopilot.profile import RcInput
from sitl.world import default_world

ROOT = Path(__file__).resolve().parents[2]
CLIMB = dataclasses.replace(StationConfig(), hold_mode=HoldMode.CLIMB_RATE)
FADE_AT_S = 45.0
RISE_MAX_M = 0.3
TOUCHDOWN_MAX_MPS = 1.0
DISARM_WITHIN_S = 20.0


class Watch:
    """The simulation's truth each tick: time, height above the floor, climb, armed, mode."""

    def __init__(self, session: Any) -> None:
        self.sim = session.sitl.sitl.sim
        self.clock = session.clock
        self.rows: list[tuple[float, float, float, bool, int]] = []

    def sample(self, *_: object) -> None:
        rt = self.sim.vehicle(1)
        st = rt.autopilot.state
        tr = rt.vehicle.truth
        self.rows.append((self.clock.now_s(), -tr.pos_n[2], -tr.vel_n[2], st.armed,
                          int(st.mode)))

    def after(self, t_s: float) -> list[tuple[float, float, float, bool, int]]:
        return [r for r in self.rows if r[0] >= t_s]


def _ticks(st: Any, seconds: float) -> None:
    for _ in range(round(seconds / 0.025)):
        st.run_tick()


@contextmanager
def _holding(profile: str, faults: dict[str, Any] | None = None,
             seed: int = 3) -> Iterator[tuple[Any, Watch]]:
    """The station's climb-rate hold at 1 m, in ALT_HOLD."""
    room = default_world()
    world = dataclasses.replace(room, autopilot=AutopilotOptions(rc_input=RcInput.MIN, gps=False),
                                room_min_n=(*room.room_min_n[:2], -30.0))
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                             fix_failsafe=True)
    with LockstepSession(options, world=world, config=CLIMB, faults=faults) as session:
        st = session.first.station
        watch = Watch(session)
        st.add_listener(watch.sample)
        assert session.preflight[1].ok, session.preflight[1].summary()
        st.request_arm(wait_s=30.0)
        for _ in range(40 * 40):  # 4.x's pre-arm refuses for its first ~24 s
            st.run_tick()
            if st.snapshot(loop_stats=False).state is SupervisorState.MANUAL:
                break
        assert st.snapshot(loop_stats=False).state is SupervisorState.MANUAL
        st.alt_hold(True, 1.0, rate_mps=0.5)
        pose = st.snapshot(loop_stats=False).mocap  # the take-off spot, held as `fly` does
        assert pose is not None
        st.set_position_setpoint(PositionSetpoint(pose.pos_n[0], pose.pos_n[1],
                                                  yaw_from_quat(pose.q_nb)))
        _ticks(st, 16.0)
        snap = st.snapshot(loop_stats=False)
        assert snap.state is SupervisorState.HOLD, snap.state
        assert watch.rows[-1][4] == int(FlightMode.ALT_HOLD)
        assert watch.rows[-1][1] == pytest.approx(1.0, abs=0.2)
        yield st, watch


def _fade_outcome(watch: Watch, fade_at: float, hold_m: float = 1.0) -> tuple[float, float, float]:
    """Rise over the hold (its set point: the SITL's own ALT_HOLD wanders 13-17 cm std about
    it, the real firmware's 0.1 cm), fastest sink within 0.3 m of the floor while armed, and
    when it disarmed (from the fade's start)."""
    rows = watch.after(fade_at)
    rise = max(h for _, h, _, _, _ in rows) - hold_m
    touchdown = max((-vz for _, h, vz, armed, _ in rows if armed and h < 0.3), default=0.0)
    off = [t for t, _, _, armed, _ in rows if not armed]
    return rise, touchdown, (off[0] - fade_at) if off else float("inf")


@pytest.mark.parametrize("way", ["up", "both"])
@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_fade_holds_then_the_firmware_lands_it(profile: str, way: str) -> None:
    """15 s of fade: the last override is a climb rate the firmware holds (mid-stick in a
    steady hold) until its GCS failsafe lands it (4.x LAND after 2 s; 3.2.1 after 5 s, LAND
    with no GPS). With the downlink alive the station sees the mode change and lets go: PC
    control ends, and nothing resumes when the uplink returns."""
    faults = {"fade": way, "fade_start_s": FADE_AT_S, "fade_s": 15.0}
    with _holding(profile, faults) as (st, watch):
        t0 = watch.rows[-1][0]
        assert t0 < FADE_AT_S - 2.0, t0
        _ticks(st, FADE_AT_S + 15.0 + 10.0 - t0)
        rise, touchdown, disarm_s = _fade_outcome(watch, FADE_AT_S)
        assert rise <= RISE_MAX_M, rise
        assert touchdown <= TOUCHDOWN_MAX_MPS, touchdown
        assert disarm_s <= DISARM_WITHIN_S, disarm_s
        modes = {m for *_, m in watch.after(FADE_AT_S)}
        assert int(FlightMode.LAND) in modes
        snap = st.snapshot(loop_stats=False)
        assert snap.state is SupervisorState.DISARMED, snap.state
        # nothing resumed by itself, and the vehicle stays on the floor
        assert max(h for _, h, _, _, _ in watch.after(FADE_AT_S + disarm_s)) < 0.1
        if way == "up":  # heard all along: the vehicle's own LAND ended PC control
            states = [e.text for e in snap.events if "by itself" in e.text]
            assert states, [e.text for e in snap.events][-8:]


def test_vehicle_mode_change_ends_pc_control_and_nothing_resumes() -> None:
    """The firmware leaves ALT_HOLD by itself (its failsafe's LAND on an uplink fade): PC
    control ends at once (VEHICLE, the stick at minimum in LAND); when the uplink comes back
    before the vehicle has landed, no ALT_HOLD is asked again."""
    faults = {"fade": "up", "fade_start_s": FADE_AT_S, "fade_s": 3.0}
    with _holding("copter4", faults) as (st, watch):
        t0 = watch.rows[-1][0]
        seen: list[tuple[SupervisorState, int]] = []
        st.add_listener(lambda snap: seen.append((snap.state, snap.command.throttle_us)))
        _ticks(st, FADE_AT_S + 6.0 - t0)
        states = [s for s, _ in seen]
        assert SupervisorState.VEHICLE in states
        after = states[states.index(SupervisorState.VEHICLE):]
        assert not {SupervisorState.HOLD, SupervisorState.TAKEOFF} & set(after)
        modes = [m for *_, m in watch.after(FADE_AT_S + 3.0)]
        assert int(FlightMode.ALT_HOLD) not in modes  # nothing re-engaged after the fade


def test_kill_in_alt_hold_stabilize_minimum_throttle_and_disarm() -> None:
    """3.2.1 refuses to disarm outside a manual mode in the air: a kill asks STABILIZE, the
    throttle goes to minimum from the next tick, and the vehicle is disarmed."""
    with _holding("apm25") as (st, watch):
        t_kill = watch.rows[-1][0]
        st.kill()
        _ticks(st, 0.05)
        assert st.snapshot(loop_stats=False).command.throttle_us == 1000
        _ticks(st, 3.0)
        snap = st.snapshot(loop_stats=False)
        assert snap.state is SupervisorState.DISARMED, snap.state
        rows = watch.after(t_kill)
        off = [t for t, _, _, armed, _ in rows if not armed]
        assert off and off[0] - t_kill <= 2.0
        armed_modes = {m for _, _, _, armed, m in rows if armed}
        assert int(FlightMode.STABILIZE) in armed_modes | {m for *_, m in rows[-1:]}


def test_quit_from_alt_hold_lands_and_stays_until_disarmed() -> None:
    """The pilot's quit: LAND from ALT_HOLD, throttle minimum and heartbeats until disarmed;
    nothing lifts it again once the station has gone."""
    with _holding("apm25") as (st, watch):
        t_quit = watch.rows[-1][0]
        st.stop()
        assert st.snapshot(loop_stats=False).state is SupervisorState.RELEASED
        gone = watch.rows[-1]
        assert not gone[3] and gone[1] < 0.1 and gone[0] - t_quit <= 20.0
        assert max(h for _, h, _, _, _ in watch.after(t_quit)) <= 1.0 + RISE_MAX_M


def test_downlink_lost_holds_mid_stick_then_lands() -> None:
    """Nothing heard from the vehicle for good: the station's link-lost policy holds mid-stick
    in ALT_HOLD (the firmware holds the height) while it asks LAND, which lands it; then the
    stick at minimum so 3.2.1 disarms."""
    fade_at = FADE_AT_S
    faults = {"fade": "down", "fade_start_s": fade_at, "fade_s": 1000.0}
    with _holding("apm25", faults) as (st, watch):
        t0 = watch.rows[-1][0]
        throttles: list[tuple[SupervisorState, int]] = []
        st.add_listener(lambda snap: throttles.append((snap.state, snap.command.throttle_us)))
        _ticks(st, fade_at + 40.0 - t0)
        lost = [thr for state, thr in throttles if state is SupervisorState.LINK_LOST]
        assert lost and lost[0] == 1500, lost[:3]
        rise, touchdown, disarm_s = _fade_outcome(watch, fade_at)
        assert rise <= RISE_MAX_M and touchdown <= TOUCHDOWN_MAX_MPS, (rise, touchdown)
        assert disarm_s <= DISARM_WITHIN_S, disarm_s


def test_fly_flag_chooses_the_climb_rate_hold_and_the_summary_says_so() -> None:
    done = subprocess.run([sys.executable, "-m", "lab", "fly", "--lockstep", "--hold", "2",
                           "--hold-mode", "climb-rate", "--no-record", "--json"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    assert summary["status"] == "ok" and summary["hold_mode"] == "climb-rate"
    assert summary["error_source"] == "truth" and summary["rms_error_m"] < 0.3
