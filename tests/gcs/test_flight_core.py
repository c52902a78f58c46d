"""The flight core: a lockstep flight's recording rerun through it gives every tick's outputs
again; its landing-state rules and link-down accounting on synthetic inputs with explicit dt."""

from __future__ import annotations

from pathlib import Path

import pytest

from firmware_link.records import Dialect, FlightMode
from gcs.cli import build_parser
from gcs.commands.fly import fly
from gcs.config import StationConfig
from gcs.control.throttle_curve import ThrottleCurve
from gcs.core.flight_core import FlightCore
from gcs.core.inputs import NEVER_S, TickInputs
from gcs.core.landing import lands_on_death, may_leave, must_land
from gcs.core.link_down import LinkDownClock
from gcs.core.outputs import TickOutputs
from gcs.rerun import load_flight
from gcs.supervisor import (
    Intent,
    IntentKind,
    LinkHealth,
    SupervisorParams,
    SupervisorState,
    VehicleStatus,
)
from logs import open_recording

S = SupervisorState
DT = 0.025


# ------------------------------------------------------------------ a flight, rerun
def test_a_lockstep_flight_reruns_through_the_core_tick_for_tick(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    flown: list[tuple[TickInputs, TickOutputs]] = []
    real_step = FlightCore.step

    def step(core: FlightCore, inputs: TickInputs) -> TickOutputs:
        out = real_step(core, inputs)
        flown.append((inputs, out))
        return out

    monkeypatch.setattr(FlightCore, "step", step)
    path = tmp_path / "f.mcap"
    fly(build_parser().parse_args(["fly", "--lockstep", "--seed", "3", "--hold", "3",
                                   "-o", str(path)]))
    monkeypatch.undo()

    flight = load_flight(open_recording(path))
    core = FlightCore(flight.config, flight.curve, flight.hover_throttle, flight.supervisor)
    assert len(flight.ticks) == len(flown) > 400
    states = set()
    for k, (recorded, (inputs, out)) in enumerate(zip(flight.ticks, flown, strict=True)):
        # repr: exact floats, and a NaN equal to a NaN (a recording keeps non-finite as null)
        assert repr(recorded) == repr(inputs), f"tick {k}: inputs differ"
        again = core.step(recorded)
        assert repr(again) == repr(out), f"tick {k}: outputs differ"
        states.add(out.state)
    # the flight armed, took off and held: the rerun went through the supervisor's phases
    assert {S.ARMING, S.TAKEOFF, S.HOLD} <= states


# ------------------------------------------------------------------ landing-state rules
@pytest.mark.parametrize(("state", "land", "leave", "on_death"), [
    (S.DISARMED, False, True, False),
    (S.ARMING, True, False, True),
    (S.MANUAL, True, False, True),
    (S.SPOOL_UP, True, False, True),
    (S.TAKEOFF, True, False, True),
    (S.HOLD, True, False, True),
    (S.VEHICLE, True, False, True),
    (S.QUITTING, True, False, True),
    (S.LINK_LOST, True, False, True),
    # killed: the throttle is already at minimum and a disarm repeated; a stop waits for it,
    # a dead loop must not turn it into a LAND with the safe (hover) throttle
    (S.KILLED, True, False, False),
    (S.SILENT, False, True, False),
    (S.RELEASED, False, True, False),
])
def test_landing_rules_of_every_state(state: SupervisorState, land: bool, leave: bool,
                                      on_death: bool) -> None:
    assert (must_land(state), may_leave(state), lands_on_death(state)) == (land, leave, on_death)


# ------------------------------------------------------------------ synthetic ticks
class Ticks:
    """Feeds a flight core synthetic inputs: a vehicle heard (or not) every tick."""

    def __init__(self) -> None:
        self.params = SupervisorParams.for_dialect(Dialect.APM25)
        self.core = FlightCore(StationConfig(), ThrottleCurve.for_dialect(Dialect.APM25), None,
                               self.params)
        self.k = 0
        self.t = 10.0
        self.rx_t = self.t
        self.seen = True
        self.armed = False
        self.heard = True

    def tick(self, *intents: Intent, dt: float = DT) -> TickOutputs:
        self.k += 1
        self.t += dt
        if self.heard:
            self.rx_t = self.t
        vehicle = VehicleStatus(seen=self.seen, armed=self.armed,
                                mode=int(FlightMode.STABILIZE) if self.seen else -1,
                                heartbeat_t_s=self.rx_t if self.seen else -NEVER_S,
                                frame_age_s=self.t - self.rx_t if self.seen else NEVER_S)
        return self.core.step(TickInputs(self.k, self.t, dt, vehicle, intents=intents))

    def run(self, seconds: float, dt: float = DT) -> TickOutputs:
        out = self.tick(dt=dt)
        for _ in range(round(seconds / dt) - 1):
            out = self.tick(dt=dt)
        return out


def test_at_rest_only_when_heard_and_disarmed() -> None:
    s = Ticks()
    assert s.tick().at_rest
    s.armed = True
    assert not s.tick().at_rest
    s.armed, s.heard = False, False
    assert s.run(s.params.lost_after_s - 0.1).at_rest  # still within the link's grace
    assert not s.run(0.2).at_rest  # silent past it: the vehicle's state is not known
    unseen = Ticks()  # before the first heartbeat nothing is known
    unseen.seen = False
    assert not unseen.tick().at_rest


def test_link_down_counts_the_silence_then_each_lost_tick() -> None:
    s = Ticks()
    out = s.run(1.0)
    assert out.supervisor.link is LinkHealth.OK and out.link_down_s == 0.0
    s.heard = False
    out = s.run(s.params.lost_after_s - 0.1)
    assert out.supervisor.link is LinkHealth.DEGRADED and out.link_down_s == 0.0
    out = s.tick(dt=0.15)  # the first lost tick: its dt and the silence before it
    assert out.link_lost
    first = out.link_down_s
    assert first == pytest.approx(0.15 + (s.t - s.rx_t), abs=1e-9)
    assert first == pytest.approx(0.15 + s.params.lost_after_s + 0.05, abs=1e-6)
    out = s.tick(dt=0.1)
    assert out.link_down_s == pytest.approx(first + 0.1, abs=1e-9)
    s.heard = True
    out = s.run(1.0)
    assert not out.link_lost and out.link_down_s == pytest.approx(first + 0.1, abs=1e-9)


def test_link_down_clock_alone() -> None:
    c = LinkDownClock()
    assert c.update(LinkHealth.OK, 0.0, DT) == 0.0
    assert c.update(LinkHealth.DEGRADED, 0.5, DT) == 0.0
    assert c.update(LinkHealth.LOST, 1.6, 0.02) == pytest.approx(1.62)
    assert c.update(LinkHealth.LOST, 1.62, 0.02) == pytest.approx(1.64)
    assert c.update(LinkHealth.OK, 0.0, 0.02) == pytest.approx(1.64)
    # lost again: its silence counts again; a vehicle never heard adds only the ticks
    assert c.update(LinkHealth.LOST, 2.0, 0.03) == pytest.approx(3.67)
    fresh = LinkDownClock()
    assert fresh.update(LinkHealth.LOST, NEVER_S, 0.03) == pytest.approx(0.03)


def test_a_lost_link_while_armed_must_land_and_lands_on_death() -> None:
    s = Ticks()
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="test"))
    out = s.tick(Intent(IntentKind.ARM))
    assert out.state is S.ARMING and s.core.must_land and s.core.lands_on_death
    s.armed = True
    out = s.run(0.5)
    assert out.state is S.MANUAL and not s.core.may_leave
    s.heard = False
    out = s.run(s.params.lost_after_s + 0.2)
    assert out.state is S.LINK_LOST and out.link_lost
    assert s.core.must_land and s.core.lands_on_death and not s.core.may_leave
    # a quit while lost is noted, not obeyed: the vehicle's own failsafe lands it
    out = s.tick(Intent(IntentKind.QUIT))
    assert out.state in (S.LINK_LOST, S.SILENT)
    # the link back with the vehicle disarmed on the floor: the station may leave
    s.heard, s.armed = True, False
    out = s.run(1.0)
    assert s.core.may_leave and not s.core.must_land, out.state
