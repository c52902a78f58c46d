"""A take-off that goes wrong on the way up (#32), in lockstep on the bundled SITL: the link
dies one way, the other or both during the throttle ramp and in the sonar's blind band, the
pilot kills during the ramp, the motors spin up later than the station waited. None may climb
away, none may meet the floor faster than 1 m/s, and every one ends disarmed.

Both profiles run with the real minimum range (20 cm) and the failsafe the pre-flight fixes
(`fix_failsafe`: 4.x lands on a silent station; 3.2.1 without a GPS lands too). The phases'
times come from the seed's own flight (deterministic in lockstep); each case first checks that
its fault begins in the phase it names. Heights and arming are the simulation's truth, read
only to judge."""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable
from typing import Any

import pytest

from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from gcs.supervisor import SupervisorState
from sitl.autopilot import AutopilotOptions
from sitl.autopilot.profile import RcInput
from sitl.world import default_world

SEED = 5
TARGET_M = 1.0
FADE_S = 15.0
AFTER_S = 25.0  # watched after the fade: the failsafe's LAND from the top, and its disarm
# the take-off's phases for SEED (simulated s): the ramp and the blind band (hold, est < 0.3)
PHASES = {("copter4", "ramp"): 11.0, ("copter4", "band"): 12.7,
          ("apm25", "ramp"): 10.5, ("apm25", "band"): 12.0}
CLIMB_LIMIT_M = 1.5  # above the floor: no runaway (the target is 1 m)
TOUCHDOWN_MPS = 1.0


class Truth:
    """Per tick: simulated time, the station's state, the true height above the floor, armed."""

    def __init__(self, session: Any) -> None:
        self.sim = session.sitl.sitl.sim
        self.clock = session.clock
        self.rows: list[tuple[float, SupervisorState, float, bool]] = []
        self.floor_m: float | None = None

    def sample(self, snap: Any) -> None:
        rt = self.sim.vehicle(1)
        z = -rt.vehicle.truth.pos_n[2]
        if self.floor_m is None:
            self.floor_m = z
        self.rows.append((self.clock.now_s(), snap.state, z - self.floor_m,
                          rt.autopilot.state.armed))

    def state_at(self, t_s: float) -> SupervisorState:
        return next(s for t, s, _, _ in self.rows if t >= t_s)

    def after(self, t_s: float) -> list[tuple[float, SupervisorState, float, bool]]:
        return [r for r in self.rows if r[0] >= t_s]

    def touchdown_mps(self, t_s: float) -> float:
        """The fastest descent within 5 cm of the floor after `t_s` (0 if none)."""
        rows = self.after(t_s)
        worst = 0.0
        for (t0, _, h0, _), (t1, _, h1, _) in itertools.pairwise(rows):
            if h1 < 0.05 and t1 > t0:
                worst = max(worst, (h0 - h1) / (t1 - t0))
        return worst


def _fly(profile: str, seconds: float, faults: dict[str, Any] | None = None,
         during: Callable[[Any, Truth], None] | None = None,
         spool_s: float | None = None) -> Truth:
    """Take off to TARGET_M on `profile` and watch for `seconds` (simulated); `during` runs
    each tick; `spool_s` overrides how long the station waits for the motors."""
    room = default_world()
    # 3.2.1's failsafe without a GPS lands (with one it climbs to RTL_ALT: the pre-flight's job)
    world = dataclasses.replace(room, autopilot=AutopilotOptions(rc_input=RcInput.MIN,
                                                                 gps=profile != "apm25"))
    options = SessionOptions(command="fly", profile=profile, seed=SEED, record=False,
                             fix_failsafe=True)
    with LockstepSession(options, world=world, faults=faults) as session:
        st = session.first.station
        truth = Truth(session)
        st.add_listener(truth.sample)
        assert session.preflight[1].ok, session.preflight[1].summary()
        if spool_s is not None:
            sup = st.core.supervisor
            sup.p = dataclasses.replace(sup.p, spool_s=spool_s)
        st.request_arm()
        for _ in range(120):
            st.run_tick()
        st.alt_hold(True, TARGET_M, rate_mps=0.5)
        for _ in range(round(seconds / 0.025)):
            st.run_tick()
            if during is not None:
                during(st, truth)
    return truth


BLIND_CLIMB = pytest.mark.xfail(strict=True, reason=(
    "#32: the take-off's climb through the blind band flies the direct throttle 40-90 us over "
    "hover (the SITL's vehicle needs it near the floor); with the uplink gone the vehicle flies "
    "that command until its failsafe (2-5 s) and meets the 2.9 m ceiling. A blind-safe climb "
    "bounded from the lift-off on (tried: it cannot leave the SITL's floor at hover + a few "
    "tenths of a m/s²) is the blind-safe hold's item, not built here"))
CASES = [pytest.param(way, phase, profile, marks=BLIND_CLIMB if (phase, way) in {
    ("band", "up"), ("band", "both")} else ()) for way in ("up", "down", "both")
    for phase in ("ramp", "band") for profile in ("copter4", "apm25")]


@pytest.mark.parametrize(("way", "phase", "profile"), CASES)
def test_link_lost_on_the_way_up_neither_climbs_away_nor_slams_and_ends_disarmed(
        way: str, phase: str, profile: str) -> None:
    start = PHASES[(profile, phase)]
    truth = _fly(profile, start + FADE_S + AFTER_S - 3.0,
                 faults={"fade": way, "fade_start_s": start, "fade_s": FADE_S})
    want = SupervisorState.TAKEOFF if phase == "ramp" else SupervisorState.HOLD
    assert truth.state_at(start) is want
    if phase == "band":
        h = next(h for t, _, h, _ in truth.rows if t >= start)
        assert h < 0.2, h  # under the sonar's minimum range (from the floor) when it began
    after = truth.after(start)
    top = max(h for _, _, h, _ in after)
    assert top < CLIMB_LIMIT_M, f"climbed to {top:.2f} m"
    assert truth.touchdown_mps(start) <= TOUCHDOWN_MPS
    assert not after[-1][3], "still armed at the end"


@pytest.mark.parametrize("profile", ["copter4", "apm25"])
def test_kill_during_the_ramp_drops_nothing_hard_and_disarms(profile: str) -> None:
    killed: list[float] = []

    def kill_once(st: Any, truth: Truth) -> None:
        t, state, _, _ = truth.rows[-1]
        if not killed and state is SupervisorState.TAKEOFF and t >= PHASES[(profile, "ramp")]:
            st.kill()
            killed.append(t)

    truth = _fly(profile, PHASES[(profile, "ramp")] + 5.0, during=kill_once)
    assert killed
    after = truth.after(killed[0])
    assert max(h for _, _, h, _ in after) < 0.3
    assert truth.touchdown_mps(killed[0]) <= TOUCHDOWN_MPS
    assert not after[-1][3]
    assert after[-1][1] is SupervisorState.DISARMED


def test_motors_spinning_up_after_the_ramp_began_neither_leap_nor_run_away() -> None:
    """4.x holds its motors stopped 2 s after arming and spools them over MOT_SPOOL_TIME; a
    station that waited 0 s ramps into motors that are not there yet. The ramp tops out near
    hover and lift-off is felt as it comes: the climb is the hold's, not the ramp's."""
    truth = _fly("copter4", 16.0, spool_s=0.0)
    ramp = [t for t, s, _, _ in truth.rows if s is SupervisorState.TAKEOFF]
    assert ramp
    hold = truth.after(ramp[-1])
    assert hold[1][1] is SupervisorState.HOLD
    top = max(h for _, _, h, _ in hold)
    assert 0.9 < top < TARGET_M * 1.1, top
    assert truth.touchdown_mps(ramp[0]) <= TOUCHDOWN_MPS
