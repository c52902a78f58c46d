"""The teleop TUI: the thesis's LabVIEW front panel, made for a terminal.

The app never touches the link or the 25 ms loop. It redraws from `backend.view()` on a timer
(8 Hz: `set_interval` drops missed ticks, so a slow terminal only lowers the redraw rate) and
hands the pilot's intents to `backend.send()`, which queues them for the loop thread.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from rich.text import Text
from textual.app import App, ComposeResult, ScreenStackError
from textual.binding import Binding, BindingType
from textual.containers import Horizontal
from textual.widgets import Footer, RichLog

from gcs.gamepad.driver import Gamepad
from gcs.pilot import intents
from gcs.pilot.view import TeleopView
from gcs.tui.backend import TeleopBackend
from gcs.tui.help import ConfirmQuit, HelpScreen, describe
from gcs.tui.pad_panel import PadPanel
from gcs.tui.sticks import Sticks
from gcs.tui.widgets import AccelPlot, AltitudePanel, HeightPlot, LinkPanel, VehiclePanel

REDRAW_HZ = 8.0
PLOT_HZ = 4.0
STICK_HZ = 20.0
SETPOINT_STEP_M = 0.1


LIVE_BINDINGS: list[BindingType] = [
    Binding("a", "arm", "Arm"),
    Binding("d", "disarm", "Disarm"),
    Binding("space", "kill", "KILL", priority=True),
    Binding("1", "mode('STABILIZE')", "Stabilize"),
    Binding("2", "mode('ALT_HOLD')", "AltHold (onboard)"),
    Binding("l", "mode('LAND')", "Land"),
    Binding("h", "toggle_hold", "PC alt hold"),
    Binding("w", "throttle(1)", "Throttle up", show=False),
    Binding("s", "throttle(-1)", "Throttle down", show=False),
    Binding("pageup,plus", "setpoint(1)", "Setpoint up", show=False, priority=True),
    Binding("pagedown,minus", "setpoint(-1)", "Setpoint down", show=False, priority=True),
    Binding("up", "stick('pitch', 1)", "Pitch forward", show=False, priority=True),
    Binding("down", "stick('pitch', -1)", "Pitch back", show=False, priority=True),
    Binding("left", "stick('roll', -1)", "Roll left", show=False, priority=True),
    Binding("right", "stick('roll', 1)", "Roll right", show=False, priority=True),
    Binding("q", "stick('yaw', -1)", "Yaw left", show=False),
    Binding("e", "stick('yaw', 1)", "Yaw right", show=False),
    ]
REPLAY_BINDINGS: list[BindingType] = [
    Binding("p", "pause", "Play/pause"),
    Binding("right", "seek(10)", "+10 s"),
    Binding("left", "seek(-10)", "-10 s"),
    Binding("plus", "speed(2)", "Faster"),
    Binding("minus", "speed(0.5)", "Slower"),
    ]
COMMON_BINDINGS: list[BindingType] = [
    Binding("question_mark", "help", "Help"),
    Binding("ctrl+c,ctrl+q", "quit", "Quit", priority=True),
    ]


class TeleopApp(App[None]):
    """Fly and watch one vehicle from a terminal (or watch a recorded flight)."""

    CSS_PATH = "app.tcss"
    TITLE = "quadgcs"
    BINDINGS = COMMON_BINDINGS

    def __init__(
        self,
        backend: TeleopBackend,
        *,
        clock: Callable[[], float] = time.monotonic,
        redraw_timers: bool = True,
        gamepad: Gamepad | None = None,
    ) -> None:
        super().__init__()
        self.gamepad = gamepad  # when set, the pad owns the sticks (the keyboard's are off)
        self.redraw_timers = redraw_timers  # False: draw once (screenshots of a fixed view)
        self.backend = backend
        self._clock = clock
        self.sticks = Sticks()
        self._last_message_t = float("-inf")
        self._hold_on = False
        self.frozen = False  # tests freeze redraws before asserting on the screen
        self._help_text = describe([*type(self).BINDINGS, *COMMON_BINDINGS])

    def compose(self) -> ComposeResult:
        """Three panels, two graph indicators, a message log and the key hints."""
        with Horizontal(id="panels"):
            yield LinkPanel(id="link", classes="panel")
            yield VehiclePanel(id="vehicle", classes="panel")
            yield AltitudePanel(id="altitude", classes="panel")
        with Horizontal(id="plots"):
            yield HeightPlot(id="height-plot")
            yield AccelPlot(id="accel-plot")
        if self.gamepad is not None:
            yield PadPanel(id="pad")
        log = RichLog(id="messages", max_lines=500, wrap=False, markup=False)
        log.can_focus = False  # arrow keys are sticks, never scrolling
        yield log
        yield Footer()

    def on_ready(self) -> None:
        """Start the redraw and stick timers once every widget is on screen."""
        self.query_one("#link").border_title = "link"
        self.query_one("#vehicle").border_title = "vehicle"
        self.query_one("#altitude").border_title = "altitude"
        self.query_one("#messages").border_title = "messages"
        self.redraw()
        self.redraw_plots()
        self._show_pad()
        if not self.redraw_timers:
            return
        self.set_interval(1.0 / REDRAW_HZ, self.redraw)
        self.set_interval(1.0 / PLOT_HZ, self.redraw_plots)
        if self.backend.live and self.gamepad is not None:
            self.set_interval(1.0 / self.gamepad.poll_hz, self.poll_gamepad)
        elif self.backend.live:
            self.set_interval(1.0 / STICK_HZ, self.send_sticks)

    def on_unmount(self) -> None:
        """Let the backend release overrides and stop its thread."""
        self.backend.close()
        if self.gamepad is not None:
            self.gamepad.close()

    # --- display -------------------------------------------------------------------------

    def _showing(self, selector: str) -> bool:
        """Whether the active screen holds `selector`; false while the app shuts down."""
        try:
            return bool(self.screen.query(selector))
        except ScreenStackError:  # a timer that fires after the last screen was popped
            return False

    def redraw(self) -> None:
        """Copy the latest view into the panels and append new messages."""
        if self.frozen or not self._showing("#messages"):
            return  # frozen by a test, or a timer firing while the screen comes or goes
        view = self.backend.view()
        for panel in self.query(".panel").results():
            panel.view = view  # type: ignore[attr-defined]
        self._hold_on = view.altitude.hold_on
        log = self.query_one("#messages", RichLog)
        for t_s, text in view.messages:
            if t_s > self._last_message_t:
                log.write(Text(f"{t_s:8.1f}  {text}"))
        if view.messages:
            self._last_message_t = max(self._last_message_t, view.messages[-1][0])

    def redraw_plots(self) -> None:
        """Redraw the two graphs (slower than the panels: plotext costs milliseconds)."""
        if self.frozen or not self._showing("HeightPlot"):
            return
        view: TeleopView = self.backend.view()
        self.query_one(HeightPlot).show(view)
        self.query_one(AccelPlot).show(view)

    def poll_gamepad(self) -> None:
        """Read the pad, send what it asks for, show it (UI thread, at the pad's poll rate)."""
        assert self.gamepad is not None
        for intent in self.gamepad.poll(self._clock(), self.backend.view()):
            self.backend.send(intent)
        self._show_pad()

    def _show_pad(self) -> None:
        pad = self.gamepad
        if pad is not None and not self.frozen and self._showing("#pad"):
            self.query_one(PadPanel).show(pad.name, pad.source.mapping.key, pad.status)

    def send_sticks(self) -> None:
        """Hand the current stick positions to the loop (it repeats them every 25 ms)."""
        if self.gamepad is not None:
            return  # two writers of sticks would fight; the pad has them
        now = self._clock()
        self.backend.send(
            intents.Sticks(
                roll=self.sticks.value("roll", now),
                pitch=self.sticks.value("pitch", now),
                yaw=self.sticks.value("yaw", now),
                throttle_us=self.sticks.throttle_us,
            )
        )

    # --- actions -------------------------------------------------------------------------

    def action_arm(self) -> None:
        """Arm (the vehicle answers; the result shows in messages)."""
        self.backend.send(intents.Arm())

    def action_disarm(self) -> None:
        """Disarm."""
        self.backend.send(intents.Disarm())

    def action_kill(self) -> None:
        """Emergency kill: throttle cut and disarm, no confirmation."""
        self.sticks.cut()
        self.backend.send(intents.Kill())

    def action_mode(self, mode: str) -> None:
        """Change flight mode."""
        self.backend.send(intents.SetMode(mode))

    def action_toggle_hold(self) -> None:
        """Engage or release altitude hold on the PC."""
        self._hold_on = not self._hold_on
        self.backend.send(intents.AltHold(self._hold_on))

    def action_throttle(self, direction: int) -> None:
        """Throttle one step up or down."""
        self.sticks.nudge_throttle(direction)
        self.send_sticks()

    def action_setpoint(self, direction: int) -> None:
        """Altitude-hold setpoint one step up or down."""
        self.backend.send(intents.SetpointStep(direction * SETPOINT_STEP_M))

    def action_stick(self, axis: str, direction: int) -> None:
        """Deflect a self-centring stick."""
        self.sticks.push(axis, direction, self._clock())
        self.send_sticks()

    def action_pause(self) -> None:
        """Replay: play/pause."""
        self.backend.send(intents.TogglePause())

    def action_seek(self, delta_s: float) -> None:
        """Replay: jump."""
        self.backend.send(intents.Seek(delta_s))

    def action_speed(self, factor: float) -> None:
        """Replay: faster or slower."""
        self.backend.send(intents.ScaleSpeed(factor))

    def action_help(self) -> None:
        """Show every binding."""
        self.push_screen(HelpScreen(self._help_text))


class LiveTeleopApp(TeleopApp):
    """Teleop of a live vehicle."""

    BINDINGS = LIVE_BINDINGS

    async def action_quit(self) -> None:
        """Quit at once when disarmed; with the vehicle armed, ask first (quitting lands it)."""
        if not self.backend.view().vehicle.armed:
            self.exit()
            return

        def answered(quit_: bool | None) -> None:
            if quit_:
                self.exit()

        self.push_screen(ConfirmQuit(), answered)


class ReplayApp(TeleopApp):
    """The same screens on a recorded flight: play/pause, speed, seek."""

    BINDINGS = REPLAY_BINDINGS


def make_app(backend: TeleopBackend, **kwargs: Any) -> TeleopApp:
    """The live or replay app, as the backend is."""
    cls = LiveTeleopApp if backend.live else ReplayApp
    return cls(backend, **kwargs)
