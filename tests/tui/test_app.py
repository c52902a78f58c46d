"""The teleop app: bindings become intents, panels show the view, snapshots of the screens."""

from __future__ import annotations

from gcs.pilot import intents
from gcs.tui.app import make_app
from tests.tui.conftest import FixedBackend


async def test_keys_become_intents() -> None:
    backend = FixedBackend()
    app = make_app(backend)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("a", "h", "plus", "w", "w", "space", "d")
        await pilot.pause()
    kinds = [type(i) for i in backend.sent if not isinstance(i, intents.Sticks)]
    assert kinds == [intents.Arm, intents.AltHold, intents.SetpointStep, intents.Kill,
                     intents.Disarm]
    throttles = [i.throttle_us for i in backend.sent if isinstance(i, intents.Sticks)]
    assert 1050 in throttles  # two throttle steps of 25 µs before the kill
    assert throttles[-1] == 1000  # the kill put the throttle back to minimum
    assert backend.closed


async def test_arrow_keys_deflect_sticks_that_centre() -> None:
    backend = FixedBackend()
    t = [100.0]
    app = make_app(backend, clock=lambda: t[0])
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("up", "right")
        sent = [i for i in backend.sent if isinstance(i, intents.Sticks)]
        assert sent[-1].pitch > 0 and sent[-1].roll > 0
        t[0] += 5.0
        app.send_sticks()
        last = backend.sent[-1]
        assert isinstance(last, intents.Sticks)
        assert (last.roll, last.pitch, last.yaw) == (0.0, 0.0, 0.0)


async def test_panels_show_the_view() -> None:
    app = make_app(FixedBackend())
    async with app.run_test(size=(80, 24)) as pilot:
        app.redraw()
        await pilot.pause()
        link = str(app.query_one("#link").render())
        vehicle = str(app.query_one("#vehicle").render())
        altitude = str(app.query_one("#altitude").render())
    assert "apm25" in link and "318/s lost 2 bad 1" in link
    assert "ARMED" in vehicle and "87 %" in vehicle
    assert "0.996" in altitude and "1492" in altitude


async def test_help_lists_every_binding() -> None:
    app = make_app(FixedBackend())
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("question_mark")
        await pilot.pause()
        body = str(app.screen.query_one("#help-body").render())
        for key in ("space", "pageup", "up", "?", "ctrl+c"):
            assert key in body
        await pilot.press("escape")
        await pilot.pause()
        assert not app.screen.query("#help-body")


def test_snapshot_main_80x24(snap_compare) -> None:  # type: ignore[no-untyped-def]
    assert snap_compare(make_app(FixedBackend(), redraw_timers=False), terminal_size=(80, 24))


def test_snapshot_main_large(snap_compare) -> None:  # type: ignore[no-untyped-def]
    assert snap_compare(make_app(FixedBackend(), redraw_timers=False), terminal_size=(160, 48))


async def test_a_redraw_after_shutdown_is_a_no_op() -> None:
    """A redraw timer may fire once more after the last screen is gone (seen on a 2-core CI)."""
    app = make_app(FixedBackend())
    async with app.run_test(size=(80, 24)):
        pass
    app.redraw()
    app.redraw_plots()
