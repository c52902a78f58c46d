"""The teleop app with a gamepad: the pad's strip, its intents, and no keyboard sticks."""

from __future__ import annotations

from gcs.gamepad.core import PadSample, VehicleState
from gcs.gamepad.driver import Gamepad
from gcs.gamepad.mapping import PadMapping, PadSettings, load_mappings
from gcs.pilot import intents
from gcs.tui.app import make_app
from gcs.tui.pad_panel import PadPanel, gauge
from tests.tui.conftest import FixedBackend


class FakePad:
    """A `PadSource` whose sample the test sets."""

    name = "Xbox 360 Controller"

    def __init__(self) -> None:
        self.mapping: PadMapping = load_mappings().select(self.name, "xbox360")
        self.settings: PadSettings = self.mapping.settings
        self.sample: PadSample | None = PadSample({"roll": 0.0, "pitch": 0.0, "yaw": 0.0,
                                                   "throttle": 0.0})
        self.closed = False

    def read(self) -> PadSample | None:
        return self.sample

    def close(self) -> None:
        self.closed = True


def flying_pad() -> Gamepad:
    """A pad that has been read once mid-flight (deterministic status for the snapshot)."""
    pad = Gamepad(FakePad())
    sample = PadSample({"roll": 0.5, "pitch": -0.25, "yaw": 0.0, "throttle": 1.0})
    vehicle = VehicleState(armed=True, mode="STABILIZE")
    pad.pilot.step(0.0, PadSample({"roll": 0.0, "throttle": 0.0}), vehicle)
    pad.pilot.step(0.5, sample, vehicle)
    return pad


def test_gauge_marks_the_deflection() -> None:
    assert gauge(0.0) == "┈┈┈●┈┈┈"
    assert gauge(-1.0) == "●┈┈┼┈┈┈"
    assert gauge(1.0) == "┈┈┈┼┈┈●"


async def test_pad_buttons_become_intents_and_the_keyboard_sticks_are_off() -> None:
    backend = FixedBackend()
    source = FakePad()
    app = make_app(backend, gamepad=Gamepad(source), redraw_timers=False)  # polled by hand
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("up", "w")  # keyboard sticks: the pad has them, nothing is sent
        assert not [i for i in backend.sent if isinstance(i, intents.Sticks)]
        app.poll_gamepad()
        source.sample = PadSample({"roll": 0.0, "throttle": 0.0}, frozenset({"setpoint_up"}))
        app.poll_gamepad()
        assert intents.SetpointStep(0.1) in backend.sent
        assert isinstance(backend.sent[-1], intents.Sticks)
        await pilot.press("a")  # the keyboard's discrete keys still work
        assert backend.sent[-1] == intents.Arm()
        text = str(app.query_one(PadPanel).render())
        assert "pad Xbox 360 Controller [xbox] engaged" in text
    assert source.closed


def test_snapshot_gamepad_80x24(snap_compare) -> None:  # type: ignore[no-untyped-def]
    app = make_app(FixedBackend(), redraw_timers=False, gamepad=flying_pad())
    assert snap_compare(app, terminal_size=(80, 24))
