"""#32 on the bundled SITL's apm25 (ArduCopter 3.2.1 rules: LAND disarms only with the
throttle at minimum, its GCS failsafe fires 5 s after the station's last heartbeat or override
and picks RTL with a GPS, which climbs to RTL_ALT unless that is 0), in lockstep over the
in-memory MAVLink link: the real station, quitting mid-air or losing the link both ways, stays
until the vehicle is disarmed and nothing lifts it again once the station is gone.

Each case names its vehicle: the receiver at minimum (the fixtures' SITLs had one), with no GPS
(the failsafe lands) or with a GPS and RTL_ALT 0 (the pre-flight's fix: RTL at the height it is).
Heights and arming are the simulation's own truth, read only to judge.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest

from gcs.config import HoldMode, StationConfig
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from gcs.supervisor import SupervisorState
from sitl.autopilot import AutopilotOptions, FlightMode
from sitl.autopilot.profile import RcInput
from sitl.world import default_world

VEHICLES = {
    "receiver-min-no-gps": AutopilotOptions(rc_input=RcInput.MIN, gps=False),
    "receiver-min-gps-rtl-alt-0": AutopilotOptions(rc_input=RcInput.MIN, gps=True,
                                                   params=(("RTL_ALT", 0.0),)),
}
CLIMB_RATE = dataclasses.replace(StationConfig(), hold_mode=HoldMode.CLIMB_RATE)
AFTER_S = 30.0  # watched this long once the station is gone: 3.2.1's failsafe fires at 5 s


class Watch:
    """The simulation's truth each tick: height above the floor, armed, mode."""

    def __init__(self, session: Any) -> None:
        self.sim = session.sitl.sitl.sim
        self.clock = session.clock
        self.rows: list[tuple[float, float, bool, int]] = []

    def sample(self, *_: object) -> None:
        rt = self.sim.vehicle(1)
        st = rt.autopilot.state
        self.rows.append((self.clock.now_s(), -rt.vehicle.truth.pos_n[2], st.armed, int(st.mode)))

    def run_alone(self, seconds: float) -> None:
        """The simulation on its own (the station gone), sampled every 0.1 s."""
        end = self.clock.now_s() + seconds
        while self.clock.now_s() < end:
            self.clock.sleep_until(self.clock.now_s() + 0.1)
            self.sample()

    def after(self, t_s: float) -> list[tuple[float, float, bool, int]]:
        return [r for r in self.rows if r[0] >= t_s]


@contextmanager
def _flying(vehicle: str, faults: dict[str, Any] | None = None, seed: int = 3,
            config: StationConfig | None = None) -> Iterator[tuple[Any, Watch]]:
    """The station holding 1 m on the apm25 SITL with `vehicle`'s receiver and GPS (`config`:
    the station's, default the direct-throttle hold)."""
    room = default_world()
    # a tall room: a vehicle carried up blind meets no ceiling (which stalls the SITL's LAND)
    world = dataclasses.replace(room, autopilot=VEHICLES[vehicle],
                                room_min_n=(*room.room_min_n[:2], -30.0))
    options = SessionOptions(command="fly", profile="apm25", seed=seed, record=False)
    with LockstepSession(options, world=world, faults=faults, config=config) as session:
        st = session.first.station
        watch = Watch(session)
        st.add_listener(watch.sample)
        assert session.preflight[1].ok, session.preflight[1].summary()
        st.request_arm()
        _ticks(st, 3.0)
        assert st.snapshot().state is SupervisorState.MANUAL
        st.alt_hold(True, 1.0, rate_mps=0.5)
        _ticks(st, 12.0 if config is None else 16.0)
        assert watch.rows[-1][1] == pytest.approx(1.0, abs=0.15 if config is None else 0.2)
        yield st, watch


def _ticks(st: Any, seconds: float) -> None:
    for _ in range(round(seconds / 0.025)):
        st.run_tick()


@pytest.mark.parametrize("vehicle", list(VEHICLES))
def test_quit_mid_air_stays_until_disarmed_and_nothing_relaunches(vehicle: str) -> None:
    with _flying(vehicle) as (st, watch):
        t_quit = watch.rows[-1][0]
        st.stop()  # the pilot's quit: LAND, then throttle minimum and heartbeats until disarmed
        snap = st.snapshot()
        assert snap.state is SupervisorState.RELEASED
        gone = watch.rows[-1]
        assert not gone[2], "the station left an armed vehicle"
        assert gone[1] < 0.1 and gone[0] - t_quit <= 20.0
        watch.run_alone(AFTER_S)
        after = watch.after(gone[0])
        assert all(not armed for _, _, armed, _ in after)
        assert max(h for _, h, _, _ in after) < 0.1  # no RTL re-launch
        assert max(h for _, h, _, _ in watch.after(t_quit)) <= 1.0 + 0.3


@pytest.mark.parametrize("vehicle", list(VEHICLES))
def test_climb_rate_hold_link_lost_both_ways_rises_little_lands_and_stays_down(
        vehicle: str) -> None:
    """The same fade as below, with the climb-rate hold (ALT_HOLD; #32's blind-safe hold): the
    last override is a height the firmware holds for the 5 s before its failsafe, whose LAND
    (no GPS) or RTL at the current height (RTL_ALT 0) lands it; the rise stays within 0.3 m of
    the hold, and it is disarmed and stays so."""
    fade_at = 45.0
    faults = {"fade": "both", "fade_start_s": fade_at, "fade_s": 15.0}
    with _flying(vehicle, faults, config=CLIMB_RATE) as (st, watch):
        t0 = watch.rows[-1][0]
        assert t0 < fade_at - 2.0, t0
        _ticks(st, fade_at + 15.0 + 20.0 - t0)
        assert st.snapshot().state is SupervisorState.DISARMED
        rows = watch.after(fade_at)
        assert max(h for _, h, _, _ in rows) <= 1.0 + 0.3
        off = [t for t, _, armed, _ in rows if not armed]
        assert off and off[0] - fade_at <= 20.0, off[:1]
        st.stop()
        watch.run_alone(AFTER_S)
        after = watch.after(off[0])
        assert all(not armed for _, _, armed, _ in after)
        assert max(h for _, h, _, _ in after) < 0.1


@pytest.mark.parametrize("vehicle", list(VEHICLES))
def test_link_lost_both_ways_then_back_disarmed_and_stays_on_the_floor(vehicle: str) -> None:
    """15 s both ways, as the fixtures' fades: nothing heard, the station keeps asking LAND
    with heartbeats (and, past the LAND's touchdown, the throttle at minimum); the vehicle's own
    failsafe lands it meanwhile. With the link back it is disarmed, and stays so.

    Not judged here: the height in the 5 s the vehicle flies the last override blind before its
    failsafe: that is #32's blind-safe hold, which the fault suite xfails. (With the 3.2.1
    sonar's 5.9 cm steps and 4 cm shortfall in the estimator, seed 3's hold no longer swings
    1420-1680 us, and its last override no longer carries it to 18 m.)"""
    fade_at = 40.0
    faults = {"fade": "both", "fade_start_s": fade_at, "fade_s": 15.0}
    with _flying(vehicle, faults) as (st, watch):
        t0 = watch.rows[-1][0]
        assert t0 < fade_at - 2.0, t0  # holding when the fade begins
        back = fade_at + 15.0
        _ticks(st, back + 20.0 - t0)
        snap = st.snapshot()
        assert snap.state is SupervisorState.DISARMED, snap.state
        rows = watch.after(fade_at)
        off = [t for t, _, armed, _ in rows if not armed]
        assert off and off[0] - fade_at <= 35.0, off[:1]
        st.stop()
        watch.run_alone(AFTER_S)
        after = watch.after(off[0])
        assert all(not armed for _, _, armed, _ in after)
        assert max(h for _, h, _, _ in after) < 0.1
        assert FlightMode.RTL not in {m for *_, m in after} or vehicle.endswith("rtl-alt-0")


@pytest.mark.parametrize("vehicle", list(VEHICLES))
def test_downlink_lost_for_good_the_station_lands_it_and_stays_until_it_disarms(
        vehicle: str) -> None:
    """The issue's row: the vehicle's frames stop for good, the station's still arrive. Its LAND
    lands the vehicle; the station, blind, keeps heartbeats and, once that LAND has had time to
    touch down, the throttle at minimum, so 3.2.1 disarms. Until #32 it went quiet 3 s after
    the loss with its last override at hover: the landed vehicle stayed armed and its GCS
    failsafe fired on it (RTL: on the real 3.2.1 back up to 13.9 m)."""
    fade_at = 40.0
    faults = {"fade": "down", "fade_start_s": fade_at, "fade_s": 1000.0}
    with _flying(vehicle, faults) as (st, watch):
        t0 = watch.rows[-1][0]
        assert t0 < fade_at - 2.0, t0
        _ticks(st, fade_at + 60.0 - t0)
        rows = watch.after(fade_at)
        off = [t for t, _, armed, _ in rows if not armed]
        assert off and off[0] - fade_at <= 20.0, off[:1]
        assert max(h for _, h, _, _ in rows) <= 1.0 + 0.3
        assert max(h for t, h, _, _ in rows if t >= off[0]) < 0.1
        assert {m for *_, m in rows} <= {int(FlightMode.STABILIZE), int(FlightMode.LAND)}
        assert st.snapshot().state is SupervisorState.LINK_LOST  # still blind, still there
