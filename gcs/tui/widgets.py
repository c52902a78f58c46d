"""Panels of the teleop screen: each renders one part of a `TeleopView`."""

from __future__ import annotations

from rich.text import Text
from textual.reactive import reactive
from textual.widgets import Static
from textual_plotext import PlotextPlot

from gcs.pilot.view import TeleopView, fmt

# About two points per terminal column keeps a plotext redraw cheap (≈10 ms at 100 points).
PLOT_WINDOW_S = 20.0


class Panel(Static):
    """A bordered text panel that redraws when its view changes."""

    view: reactive[TeleopView | None] = reactive(None, layout=False)

    def watch_view(self, view: TeleopView | None) -> None:
        """Re-render on every new view."""
        if view is not None:
            self.update(self.render_view(view))

    def render_view(self, view: TeleopView) -> Text:
        """The panel's text for `view`."""
        raise TypeError(f"{type(self).__name__} must define render_view")


def _flag(on: bool, yes: str, no: str, *, bad_when_on: bool = False) -> Text:
    style = ("bold red" if bad_when_on else "bold green") if on else "dim"
    return Text(yes if on else no, style=style)


class LinkPanel(Panel):
    """Connection, heartbeat age, message rate, loss and corruption, signing, recording, loop."""

    def render_view(self, view: TeleopView) -> Text:
        """Link and loop health."""
        link, loop = view.link, view.loop
        text = Text()
        text.append(f"{link.url or '—'}  {link.firmware or link.dialect}")
        if link.firmware_source:
            text.append(f" · {link.firmware_source}", style="dim")
        text.append("\n")
        if link.lost:
            text.append("LINK LOST", style="bold red")
        elif link.connected:
            text.append("connected", style="bold green")
        else:
            text.append("connecting…", style="yellow")
        text.append(f"  hb {fmt(link.heartbeat_age_s, '.1f', ' s')}\n")
        text.append(f"{fmt(link.msgs_per_s, '.0f')}/s lost {link.rx_lost} bad {link.rx_bad}\n")
        text.append("signing ")
        text.append(_flag(link.signing, "on", "off"))
        text.append("  rec ")
        text.append(_flag(link.recording is not None, "on", "off"))
        text.append("\n")
        if link.fwd_stations is not None:
            text.append(f"fwd {link.fwd_stations} stn  ")
            text.append(f"rc refused {link.fwd_refused_overrides}\n",
                        style="yellow" if link.fwd_refused_overrides else "dim")
        text.append(f"loop {fmt(loop.period_ms, '.1f')} jit99 {fmt(loop.jitter_p99_ms, '.2f')}\n")
        text.append(f"cpu {fmt(loop.compute_ms, '.2f')} ms  ovr {loop.overruns}")
        return text


class VehiclePanel(Panel):
    """Mode, armed, failsafe, battery and attitude."""

    def render_view(self, view: TeleopView) -> Text:
        """Vehicle state."""
        v = view.vehicle
        text = Text()
        text.append(f"{v.mode or '—'}  ", style="bold")
        text.append(_flag(v.armed, "ARMED", "disarmed", bad_when_on=True))
        text.append("\n")
        if v.failsafe:
            text.append("FAILSAFE\n", style="bold red reverse")
        else:
            text.append("no failsafe\n", style="dim")
        text.append(f"batt {fmt(v.battery_v, '.2f', ' V')} {fmt(v.battery_pct, 'd', ' %')}\n")
        text.append(f"roll  {fmt(v.roll_deg, '+6.1f', '°')}\n")
        text.append(f"pitch {fmt(v.pitch_deg, '+6.1f', '°')}\n")
        text.append(f"yaw   {fmt(v.yaw_deg, '+6.1f', '°')}")
        if view.replay:
            text.append(f"\n{view.replay}", style="bold cyan")
        return text


class AltitudePanel(Panel):
    """Altitude from sonar, accelerometer and fused, the setpoint and vertical motion."""

    def render_view(self, view: TeleopView) -> Text:
        """Altitude sources side by side."""
        a = view.altitude
        text = Text()
        text.append("hold ")
        text.append(_flag(a.hold_on, "ON", "off"))
        text.append(f"  sp {fmt(a.setpoint_m, '.2f', ' m')}\n")
        text.append(f"fused {fmt(a.fused_m, '.3f', ' m')}", style="bold")
        text.append(f" ({fmt(a.truth_m, '.3f')})\n" if a.truth_m is not None else "\n",
                    style="dim")
        text.append(f"sonar {fmt(a.sonar_m, '.3f', ' m')}\n")
        text.append(f"accel {fmt(a.accel_m, '.3f', ' m')}\n")
        text.append(f"climb {fmt(a.climb_mps, '+.2f', ' m/s')}\n")
        text.append(f"acc↑  {fmt(a.acc_up_mps2, '+.2f', ' m/s²')}\n")
        text.append(f"thr   {fmt(a.throttle_us, 'd', ' µs')}")
        return text


class HeightPlot(PlotextPlot):
    """The thesis's height graph indicator: fused estimate, setpoint and sonar."""

    def show(self, view: TeleopView) -> None:
        """Redraw from the view's history."""
        plt = self.plt
        plt.clear_data()
        plt.title("height (m)")
        hist = [h for h in view.alt_history if h[0] >= view.t_s - PLOT_WINDOW_S]
        if hist:
            t0 = view.t_s
            xs = [h[0] - t0 for h in hist]
            for idx, label in ((1, "fused"), (2, "setpoint"), (3, "sonar")):
                pts = [(x, h[idx]) for x, h in zip(xs, hist, strict=True) if h[idx] is not None]
                if pts:
                    xs_, ys_ = [p[0] for p in pts], [p[1] for p in pts]
                    plt.plot(xs_, ys_, label=label, marker="braille")
        self.refresh()


class AccelPlot(PlotextPlot):
    """The thesis's acceleration graph indicator: vertical acceleration, positive up."""

    def show(self, view: TeleopView) -> None:
        """Redraw from the view's history."""
        plt = self.plt
        plt.clear_data()
        plt.title("vertical acc (m/s²)")
        since = view.t_s - PLOT_WINDOW_S
        hist = [h for h in view.acc_history if h[0] >= since and h[1] is not None]
        if hist:
            plt.plot([h[0] - view.t_s for h in hist], [h[1] for h in hist], marker="braille")
        self.refresh()
