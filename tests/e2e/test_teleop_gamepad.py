"""The teleop TUI flies the bundled SITL with a gamepad: SDL's virtual joystick, read through
the same SDL joystick API as a real pad, and Textual's Pilot for the screen.

The station runs in its own process, as `quadgcs teleop --gamepad` runs it; the pad is read on
the app's side. The tests move sticks and press buttons on the virtual pad, pull it out
mid-flight and plug it back, and watch only what the pilot sees: the views. Three flights: PC
hold by button and a climb by stick, unplugged mid-hold (the hold goes on) and plugged back;
a manual throttle unplugged (LAND after 2 s); a climb by throttle in STABILIZE and a kill.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from gcs.gamepad.core import PadPhase
from gcs.gamepad.driver import Gamepad
from gcs.gamepad.mapping import load_mappings
from gcs.gamepad.sdl_pad import SdlPad
from gcs.pilot.view import TeleopView
from gcs.station.session import SessionOptions
from gcs.tui.app import TeleopApp, make_app
from gcs.tui.pad_panel import PadPanel
from gcs.tui.process_backend import ProcessBackend
from tests.e2e.test_teleop_tui import truth_alt, wait_until
from tests.gamepad.virtual_pad import VirtualPad

pytestmark = [pytest.mark.e2e, pytest.mark.timeout(240)]
ROLES = {"start": "arm", "a": "hold", "b": "kill", "dpup": "setpoint_up", "x": "stabilize"}


@pytest.fixture
def vpad() -> Iterator[VirtualPad]:
    pad = VirtualPad()  # "Xbox 360 Controller": the bundled [pads.xbox] entry
    yield pad
    pad.close()


async def wait_pad(pilot, app: TeleopApp, cond: Callable[[Gamepad], bool],  # type: ignore[no-untyped-def]
                   timeout_s: float) -> None:
    """Let the app poll the pad until `cond` holds (or fail at the deadline)."""
    assert app.gamepad is not None
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if cond(app.gamepad):
            return
        await pilot.pause(0.05)
    raise AssertionError(f"pad condition not met within {timeout_s} s: {app.gamepad.status}; "
                         f"last view {backend_of(app).view()}")


def backend_of(app: TeleopApp) -> ProcessBackend:
    assert isinstance(app.backend, ProcessBackend)
    return app.backend


async def press(pilot, app: TeleopApp, vpad: VirtualPad, button: str,  # type: ignore[no-untyped-def]
                backend: ProcessBackend, cond: Callable[[TeleopView], bool],
                timeout_s: float) -> TeleopView:
    """Hold `button` down until the pad has read it and the vehicle shows `cond`, then let go
    and wait for the pad to read the release (so that the next press is a new edge)."""
    role = ROLES[button]
    vpad.button(button, True)
    try:
        await wait_pad(pilot, app, lambda g: role in g.status.buttons, 5.0)
        return await wait_until(pilot, backend, cond, timeout_s)
    finally:
        vpad.button(button, False)
        await wait_pad(pilot, app, lambda g: role not in g.status.buttons, 5.0)


def start(tmp_path: Path) -> tuple[ProcessBackend, TeleopApp]:
    gamepad = Gamepad(SdlPad(None, load_mappings()))
    backend = ProcessBackend(SessionOptions(command="teleop", seed=7, output=tmp_path))
    return backend, make_app(backend, gamepad=gamepad)


async def take_off_in_pc_hold(pilot, app: TeleopApp, vpad: VirtualPad,  # type: ignore[no-untyped-def]
                              backend: ProcessBackend) -> TeleopView:
    """Arm by button, PC hold by button (take-off), climb by stick to about 0.6 m."""
    await wait_pad(pilot, app, lambda g: g.status.phase is PadPhase.ENGAGED, 5.0)
    await press(pilot, app, vpad, "start", backend, lambda v: v.vehicle.armed, 20.0)
    await press(pilot, app, vpad, "a", backend, lambda v: v.altitude.hold_on, 5.0)
    await wait_until(pilot, backend, lambda v: v.altitude.setpoint_m is not None, 20.0)
    vpad.axis("lefty", -1.0)  # throttle stick up: the set point climbs at climb_rate_mps
    await wait_until(pilot, backend, lambda v: (v.altitude.setpoint_m or 0.0) >= 0.6, 10.0)
    vpad.axis("lefty", 0.0)
    await wait_until(pilot, backend, lambda v: truth_alt(v) > 0.5, 20.0)
    return await settled(pilot, backend)


async def settled(pilot, backend: ProcessBackend, timeout_s: float = 10.0,  # type: ignore[no-untyped-def]
                  still_s: float = 0.5) -> TeleopView:
    """The first view after the set point has stopped moving (it follows the target on the
    controller's profile, so it arrives a little after the last step)."""
    deadline = time.monotonic() + timeout_s
    last, since = backend.view().altitude.setpoint_m, time.monotonic()
    while time.monotonic() < deadline:
        await pilot.pause(0.1)
        view = backend.view()
        if view.altitude.setpoint_m != last:
            last, since = view.altitude.setpoint_m, time.monotonic()
        elif time.monotonic() - since >= still_s:
            return view
    raise AssertionError(f"set point still moving after {timeout_s} s: {last}")


async def test_pad_flies_pc_hold_and_the_hold_survives_an_unplug(
        tmp_path: Path, vpad: VirtualPad) -> None:
    backend, app = start(tmp_path)
    async with app.run_test(size=(80, 26)) as pilot:
        view = await take_off_in_pc_hold(pilot, app, vpad, backend)
        setpoint = view.altitude.setpoint_m
        assert setpoint is not None
        panel = str(app.query_one(PadPanel).render())
        assert "pad Xbox 360 Controller [xbox] engaged" in panel and "thr" in panel
        vpad.axis("rightx", 0.8)  # rolling when the cable comes out
        await wait_pad(pilot, app, lambda g: g.status.roll > 0.5, 5.0)
        vpad.unplug()
        unplugged_at = time.monotonic()
        await wait_pad(pilot, app, lambda g: g.status.phase is PadPhase.UNPLUGGED, 5.0)
        # the policy: the PC keeps holding, level, well past the manual-throttle timeout
        while time.monotonic() < unplugged_at + 5.0:
            v = backend.view()
            assert v.vehicle.armed and v.altitude.hold_on and v.vehicle.mode == "STABILIZE"
            assert v.altitude.setpoint_m == pytest.approx(setpoint, abs=1e-6)
            await pilot.pause(0.1)
        v = backend.view()
        assert abs(truth_alt(v) - setpoint) < 0.15 and abs(v.vehicle.roll_deg or 0.0) < 5.0
        app.redraw()
        await pilot.pause()
        assert "unplugged" in str(app.query_one(PadPanel).render())
        # back in: nothing until the throttle is centred and a button pressed
        vpad.plug()
        vpad.axis("lefty", -1.0)
        await wait_pad(pilot, app, lambda g: g.status.phase is PadPhase.WAITING, 5.0)
        await press(pilot, app, vpad, "dpup", backend, lambda v: True, 1.0)
        assert app.gamepad is not None and app.gamepad.status.phase is PadPhase.WAITING
        assert backend.view().altitude.setpoint_m == pytest.approx(setpoint, abs=1e-6)
        vpad.axis("lefty", 0.0)
        # this press only gives the pad the sticks back
        await press(pilot, app, vpad, "dpup", backend, lambda v: True, 1.0)
        assert app.gamepad.status.phase is PadPhase.ENGAGED
        await pilot.pause(0.3)  # a set-point step would show within a view or two
        assert backend.view().altitude.setpoint_m == pytest.approx(setpoint, abs=1e-6)
        await press(pilot, app, vpad, "dpup", backend,
                    lambda v: (v.altitude.setpoint_m or 0.0) > setpoint + 0.05, 3.0)
        # kill by button
        await press(pilot, app, vpad, "b", backend, lambda v: not v.vehicle.armed, 10.0)
        await wait_until(pilot, backend, lambda v: truth_alt(v) < 0.15, 10.0)
        assert any("KILL" in text for _, text in backend.view().messages)
    assert backend.error is None
    assert any(tmp_path.glob("*.mcap"))


async def test_pad_unplugged_under_manual_throttle_lands_after_the_timeout(
        tmp_path: Path, vpad: VirtualPad) -> None:
    backend, app = start(tmp_path)
    async with app.run_test(size=(80, 26)) as pilot:
        await take_off_in_pc_hold(pilot, app, vpad, backend)
        # PC hold off by button: the pad's throttle starts where the hold left it, so the
        # supervisor hands it the vehicle at once — a manual throttle
        def pickups(v: TeleopView) -> int:
            return sum("the pilot's throttle has the vehicle" in text for _, text in v.messages)

        before = pickups(backend.view())  # one already: at arming, at minimum
        await press(pilot, app, vpad, "a", backend, lambda v: not v.altitude.hold_on, 5.0)
        await wait_until(pilot, backend, lambda v: pickups(v) > before, 5.0)
        assert backend.view().vehicle.mode == "STABILIZE" and backend.view().vehicle.armed
        vpad.unplug()
        unplugged_at = time.monotonic()
        # the policy: nobody flies a manual throttle, so after lost_land_s (2 s) the pad asks
        # for LAND — through the supervisor, like a pilot's key
        commanded = "unplugged: LAND commanded"
        while app.gamepad.status.note != commanded:
            assert time.monotonic() < unplugged_at + 4.0, app.gamepad.status
            v = backend.view()
            assert v.vehicle.armed and v.vehicle.mode == "STABILIZE", v.vehicle
            await pilot.pause(0.02)
        asked_after = time.monotonic() - unplugged_at
        assert 1.95 <= asked_after <= 3.0, asked_after
        view = await wait_until(pilot, backend, lambda v: v.vehicle.mode == "LAND", 8.0)
        assert any("mode LAND requested" in text for _, text in view.messages)
        assert not view.altitude.hold_on
        await wait_until(pilot, backend, lambda v: not v.vehicle.armed, 30.0)
        assert truth_alt(backend.view()) < 0.15
        # back in after the landing (disarmed: the pad's throttle rests at minimum), a button
        # gives the pad the sticks again
        vpad.plug()
        await wait_pad(pilot, app, lambda g: g.status.phase is PadPhase.WAITING, 5.0)
        await press(pilot, app, vpad, "x", backend, lambda v: True, 1.0)
        assert app.gamepad.status.phase is PadPhase.ENGAGED
    assert backend.error is None


async def test_pad_climbs_by_throttle_in_stabilize_and_kills(
        tmp_path: Path, vpad: VirtualPad) -> None:
    backend, app = start(tmp_path)
    async with app.run_test(size=(80, 26)) as pilot:
        await wait_pad(pilot, app, lambda g: g.status.phase is PadPhase.ENGAGED, 5.0)
        await press(pilot, app, vpad, "start", backend, lambda v: v.vehicle.armed, 20.0)
        # the accumulating throttle: stick up raises it, centred it stays where it was put
        vpad.axis("lefty", -1.0)
        await wait_until(pilot, backend, lambda v: truth_alt(v) > 0.2, 20.0)
        vpad.axis("lefty", 0.0)
        await wait_pad(pilot, app, lambda g: g.status.throttle_axis == 0.0, 5.0)
        assert app.gamepad is not None
        put = app.gamepad.status.throttle_us
        # the supervisor lets it through (on a loaded machine the pad's last intent can reach
        # the loop a tick or two after the pad settles: wait for it, do not race it)
        view = await wait_until(pilot, backend, lambda v: truth_alt(v) > 0.35
                                and v.altitude.throttle_us == put, 10.0)
        assert view.vehicle.mode == "STABILIZE" and not view.altitude.hold_on
        assert app.gamepad.status.throttle_us == put  # stayed where it was put
        await press(pilot, app, vpad, "b", backend, lambda v: not v.vehicle.armed, 10.0)
        assert app.gamepad.status.throttle_us == 1000
        await wait_until(pilot, backend, lambda v: truth_alt(v) < 0.15, 10.0)
    assert backend.error is None
