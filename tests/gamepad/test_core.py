"""The pure gamepad core: shaping, buttons to intents, throttle by who holds the altitude, and
what an unplugged and re-plugged pad does. Time is passed in; nothing here sleeps."""

from __future__ import annotations

import pytest

from gcs.gamepad.core import GamepadPilot, PadPhase, PadSample, VehicleState, shape
from gcs.gamepad.mapping import PadSettings
from gcs.pilot import intents

DT = 0.02
DISARMED = VehicleState()
MANUAL = VehicleState(armed=True, mode="STABILIZE")
PC_HOLD = VehicleState(armed=True, hold_on=True, mode="STABILIZE")
ONBOARD_HOLD = VehicleState(armed=True, mode="ALT_HOLD")
LANDING = VehicleState(armed=True, mode="LAND")


def pad(throttle: float = 0.0, roll: float = 0.0, pitch: float = 0.0, yaw: float = 0.0,
        *buttons: str) -> PadSample:
    return PadSample({"roll": roll, "pitch": pitch, "yaw": yaw, "throttle": throttle},
                     frozenset(buttons))


def sticks(out: list[intents.Intent]) -> intents.Sticks:
    found = [i for i in out if isinstance(i, intents.Sticks)]
    assert len(found) == 1, out
    return found[0]


def others(out: list[intents.Intent]) -> list[intents.Intent]:
    return [i for i in out if not isinstance(i, intents.Sticks)]


class Clock:
    """Steps a pilot at the poll period."""

    def __init__(self, pilot: GamepadPilot) -> None:
        self.pilot, self.t = pilot, 0.0

    def step(self, sample: PadSample | None, vehicle: VehicleState) -> list[intents.Intent]:
        self.t += DT
        return self.pilot.step(self.t, sample, vehicle)

    def run(self, seconds: float, sample: PadSample | None,
            vehicle: VehicleState) -> list[intents.Intent]:
        out: list[intents.Intent] = []
        for _ in range(round(seconds / DT)):
            out += self.step(sample, vehicle)
        return out


def test_shape_deadzone_and_expo() -> None:
    assert shape(0.05, 0.08, 0.3) == 0.0
    assert shape(1.0, 0.08, 0.3) == 1.0 and shape(-1.0, 0.08, 0.3) == -1.0
    assert shape(1.7, 0.1, 0.0) == 1.0  # out-of-range input clamps
    assert shape(0.081, 0.08, 0.0) == pytest.approx(0.001 / 0.92)  # no step at the edge
    assert 0.0 < shape(0.5, 0.0, 0.5) < 0.5  # expo: softer near centre
    assert shape(-0.5, 0.0, 0.5) == -shape(0.5, 0.0, 0.5)


def test_buttons_are_edges_and_map_to_intents() -> None:
    c = Clock(GamepadPilot())
    assert c.step(pad(), DISARMED) and c.pilot.phase is PadPhase.ENGAGED
    assert others(c.step(pad(0, 0, 0, 0, "arm"), DISARMED)) == [intents.Arm()]
    assert others(c.step(pad(0, 0, 0, 0, "arm"), DISARMED)) == []  # held, not pressed again
    out = c.step(pad(0, 0, 0, 0, "hold", "setpoint_up", "land"), MANUAL)
    assert others(out) == [intents.AltHold(True), intents.SetpointStep(0.1),
                           intents.SetMode("LAND")]
    out = c.step(pad(0, 0, 0, 0, "hold", "setpoint_down", "stabilize", "alt_hold"), PC_HOLD)
    assert others(out) == [intents.SetpointStep(-0.1), intents.SetMode("STABILIZE"),
                           intents.SetMode("ALT_HOLD")]
    out = c.step(pad(0, 0, 0, 0, "hold"), PC_HOLD)
    assert others(out) == []
    c.step(pad(), PC_HOLD)
    assert others(c.step(pad(0, 0, 0, 0, "hold"), PC_HOLD)) == [intents.AltHold(False)]


def test_kill_wins_and_cuts_the_throttle() -> None:
    c = Clock(GamepadPilot())
    c.step(pad(), MANUAL)
    c.run(1.0, pad(1.0), MANUAL)
    assert sticks(c.step(pad(1.0), MANUAL)).throttle_us > 1300
    out = c.step(pad(1.0, 0, 0, 0, "kill", "arm", "hold"), MANUAL)
    assert others(out) == [intents.Kill()] and sticks(out).throttle_us == 1000


def test_accumulated_throttle_stays_where_put_and_rests_at_minimum_disarmed() -> None:
    c = Clock(GamepadPilot(PadSettings(throttle_rate_us_per_s=400.0, expo=0.0, deadzone=0.0)))
    assert sticks(c.step(pad(), MANUAL)).throttle_us == 1000
    c.run(1.0, pad(1.0), MANUAL)  # full up for a second: +400 us
    assert sticks(c.step(pad(0.0), MANUAL)).throttle_us == pytest.approx(1400, abs=9)
    assert sticks(c.run(2.0, pad(0.0), MANUAL)[-1:]).throttle_us == pytest.approx(1400, abs=9)
    c.run(0.5, pad(-1.0), MANUAL)
    assert sticks(c.step(pad(), MANUAL)).throttle_us == pytest.approx(1200, abs=9)
    assert sticks(c.step(pad(), DISARMED)).throttle_us == 1000  # disarmed: ready to arm


def test_a_ui_stall_is_not_one_big_throttle_jump() -> None:
    p = GamepadPilot(PadSettings(expo=0.0, deadzone=0.0))
    p.step(0.0, pad(), MANUAL)
    assert sticks(p.step(10.0, pad(1.0), MANUAL)).throttle_us <= 1000 + 400 * 0.2 + 1


def test_full_throttle_is_the_sticks_position() -> None:
    c = Clock(GamepadPilot(PadSettings(throttle="full")))
    assert c.pilot.step(0.0, pad(-1.0), DISARMED)[-1] == intents.Sticks(0.0, 0.0, 0.0, 1000)
    assert sticks(c.step(pad(0.3, 0.5, -0.5, 1.0), MANUAL)).throttle_us == 1650
    s = sticks(c.step(pad(0.3, 0.5, -0.5, 1.0), MANUAL))
    assert s.roll == shape(0.5, 0.08, 0.3) and s.pitch == -s.roll and s.yaw == 1.0


def test_under_pc_hold_the_throttle_moves_the_setpoint() -> None:
    c = Clock(GamepadPilot(PadSettings(climb_rate_mps=0.4, expo=0.0, deadzone=0.0)))
    c.step(pad(), PC_HOLD)
    out = c.run(1.0, pad(1.0), PC_HOLD)
    climbed = sum(i.delta_m for i in out if isinstance(i, intents.SetpointStep))
    assert climbed == pytest.approx(0.4, abs=0.02)
    assert not [i for i in c.run(1.0, pad(0.0), PC_HOLD) if isinstance(i, intents.SetpointStep)]


def test_under_the_vehicles_alt_hold_centre_is_mid_stick() -> None:
    c = Clock(GamepadPilot(PadSettings(expo=0.0, deadzone=0.0)))
    c.step(pad(), DISARMED)
    assert sticks(c.step(pad(0.0), ONBOARD_HOLD)).throttle_us == 1500
    assert sticks(c.step(pad(0.5), ONBOARD_HOLD)).throttle_us == 1750


def test_first_pad_needs_a_neutral_throttle_then_a_button() -> None:
    c = Clock(GamepadPilot(PadSettings(throttle="full")))
    out = c.step(pad(0.0), DISARMED)  # a spring-centred stick in full mode: 1500 us
    assert c.pilot.phase is PadPhase.WAITING and sticks(out).throttle_us == 1000
    assert "throttle down" in c.pilot.status.note
    assert others(c.step(pad(0.0, 0, 0, 0, "arm"), DISARMED)) == []  # not neutral: nothing
    c.step(pad(-1.0), DISARMED)
    assert c.pilot.phase is PadPhase.WAITING
    assert others(c.step(pad(-1.0, 0, 0, 0, "arm"), DISARMED)) == []  # takes the sticks only
    assert c.pilot.phase is PadPhase.ENGAGED
    c.step(pad(-1.0), DISARMED)
    assert others(c.step(pad(-1.0, 0, 0, 0, "arm"), DISARMED)) == [intents.Arm()]


def test_unplugged_in_pc_hold_keeps_holding_level() -> None:
    c = Clock(GamepadPilot())
    c.step(pad(0.0, 0.6, 0.6, 0.6), PC_HOLD)
    out = c.run(10.0, None, PC_HOLD)
    assert not others(out)  # no LAND: the PC holds the altitude
    assert {(s.roll, s.pitch, s.yaw) for s in out if isinstance(s, intents.Sticks)} == {(0, 0, 0)}
    assert c.pilot.phase is PadPhase.UNPLUGGED
    assert c.pilot.status.note == "unplugged: sticks centred"


def test_unplugged_under_manual_throttle_lands_after_the_timeout() -> None:
    c = Clock(GamepadPilot(PadSettings(lost_land_s=2.0, expo=0.0, deadzone=0.0)))
    c.step(pad(), MANUAL)
    c.run(1.0, pad(1.0, 0.5), MANUAL)
    held = sticks(c.step(pad(0.0, 0.5), MANUAL)).throttle_us
    out = c.run(1.9, None, MANUAL)
    assert not others(out)
    assert {s.throttle_us for s in out if isinstance(s, intents.Sticks)} == {held}
    assert sticks(out[-1:]).roll == 0.0
    assert "LAND in 0.1 s" in c.pilot.status.note
    out = c.run(0.2, None, MANUAL)
    assert others(out) == [intents.SetMode("LAND")]
    assert sticks(out[-1:]).throttle_us == 1000
    assert others(c.run(1.0, None, MANUAL)) == [intents.SetMode("LAND")]  # not seen: again
    assert not others(c.run(5.0, None, LANDING))  # LAND seen: no more asking


def test_hold_switched_off_while_unplugged_starts_the_timeout_then() -> None:
    c = Clock(GamepadPilot(PadSettings(lost_land_s=2.0)))
    c.step(pad(), PC_HOLD)
    c.run(5.0, None, PC_HOLD)
    assert not others(c.run(1.9, None, MANUAL))
    assert others(c.run(0.2, None, MANUAL)) == [intents.SetMode("LAND")]


def test_disarmed_unplugged_asks_nothing() -> None:
    c = Clock(GamepadPilot())
    c.step(pad(), DISARMED)
    assert not others(c.run(5.0, None, DISARMED))


def test_replug_in_hold_needs_a_centred_throttle_and_a_button() -> None:
    c = Clock(GamepadPilot(PadSettings(expo=0.0, deadzone=0.1)))
    c.step(pad(), PC_HOLD)
    c.run(1.0, None, PC_HOLD)
    out = c.step(pad(0.8, 0.9), PC_HOLD)  # back, throttle up and rolling: ignored
    assert c.pilot.phase is PadPhase.WAITING and sticks(out).roll == 0.0
    assert not [i for i in out if isinstance(i, intents.SetpointStep)]
    assert "throttle to centre" in c.pilot.status.note
    c.step(pad(0.8, 0.9, 0, 0, "hold"), PC_HOLD)
    assert c.pilot.phase is PadPhase.WAITING
    c.step(pad(0.0), PC_HOLD)
    assert c.pilot.phase is PadPhase.WAITING  # centred, but no button yet
    assert others(c.step(pad(0.0, 0, 0, 0, "hold"), PC_HOLD)) == []  # consumed, not a toggle
    assert c.pilot.phase is PadPhase.ENGAGED
    assert sticks(c.step(pad(0.0, 0.9), PC_HOLD)).roll == shape(0.9, 0.1, 0.0)


def test_replug_after_land_needs_the_throttle_at_minimum() -> None:
    c = Clock(GamepadPilot(PadSettings(throttle="full", lost_land_s=2.0)))
    c.step(pad(-1.0), MANUAL)
    c.run(0.5, pad(0.1), MANUAL)
    c.run(2.5, None, MANUAL)
    assert c.pilot.status.note == "unplugged: LAND commanded"
    c.step(pad(0.1, 0, 0, 0, "a"), LANDING)
    c.step(pad(0.1, 0, 0, 0, "arm"), LANDING)
    assert c.pilot.phase is PadPhase.WAITING and "throttle down" in c.pilot.status.note
    c.step(pad(-1.0), LANDING)
    c.step(pad(-1.0, 0, 0, 0, "arm"), LANDING)
    assert c.pilot.phase is PadPhase.ENGAGED and c.pilot.status.note == ""


def test_replug_within_the_timeout_picks_up_the_held_throttle() -> None:
    # accumulate: the pad's throttle carries on from the one the station holds, so a button
    # alone gives it back (no jump, no drop); the timeout runs until it does
    c = Clock(GamepadPilot(PadSettings(lost_land_s=2.0, expo=0.0, deadzone=0.0)))
    c.step(pad(), MANUAL)
    c.run(1.0, pad(1.0), MANUAL)
    held = sticks(c.step(pad(0.0), MANUAL)).throttle_us
    c.run(1.0, None, MANUAL)
    c.step(pad(0.0), MANUAL)
    assert c.pilot.phase is PadPhase.WAITING and "throttle ok" in c.pilot.status.note
    assert sticks(c.step(pad(0.0, 0, 0, 0, "arm"), MANUAL)).throttle_us == held
    assert c.pilot.phase is PadPhase.ENGAGED


def test_waiting_pad_still_lands_a_manual_vehicle_in_time() -> None:
    c = Clock(GamepadPilot(PadSettings(throttle="full", lost_land_s=2.0)))
    c.step(pad(-1.0), MANUAL)
    c.run(0.5, pad(0.0), MANUAL)
    c.run(1.0, None, MANUAL)
    out = c.run(1.2, pad(0.6), MANUAL)  # back, but the throttle meets neither minimum nor 1500
    assert c.pilot.phase is PadPhase.WAITING
    assert others(out) == [intents.SetMode("LAND")]


def test_kill_works_while_waiting() -> None:
    c = Clock(GamepadPilot(PadSettings(throttle="full")))
    c.step(pad(0.5), MANUAL)
    assert c.pilot.phase is PadPhase.WAITING
    out = c.step(pad(0.5, 0, 0, 0, "kill"), MANUAL)
    assert others(out) == [intents.Kill()] and sticks(out).throttle_us == 1000
    assert c.pilot.phase is PadPhase.WAITING


def test_pc_hold_let_go_hands_over_the_holds_throttle() -> None:
    c = Clock(GamepadPilot(PadSettings(expo=0.0, deadzone=0.0)))
    c.step(pad(), PC_HOLD)
    c.run(1.0, pad(0.5), PC_HOLD)  # moves the set point, not the throttle
    let_go = VehicleState(armed=True, mode="STABILIZE", throttle_us=1483)
    assert sticks(c.step(pad(), let_go)).throttle_us == 1483
    assert sticks(c.run(0.5, pad(), let_go)[-1:]).throttle_us == 1483
    # a hold that ends in LAND (the vehicle's own throttle) hands nothing over
    c = Clock(GamepadPilot())
    c.step(pad(), PC_HOLD)
    assert sticks(c.step(pad(), VehicleState(armed=True, mode="LAND", throttle_us=1000))
                  ).throttle_us == 1000
    assert sticks(c.step(pad(), VehicleState(armed=True, mode="STABILIZE",
                                             throttle_us=1450))).throttle_us == 1000


def test_unplugged_in_the_vehicles_alt_hold_centres_the_throttle_too() -> None:
    c = Clock(GamepadPilot(PadSettings(lost_land_s=2.0, expo=0.0, deadzone=0.0)))
    c.step(pad(), DISARMED)
    c.step(pad(0.4), ONBOARD_HOLD)  # climbing in the vehicle's ALT_HOLD
    out = c.run(5.0, None, ONBOARD_HOLD)
    assert not others(out)  # the vehicle holds its own altitude: no LAND
    assert {s.throttle_us for s in out if isinstance(s, intents.Sticks)} == {1500}
