"""One strip of the teleop screen for the gamepad: its name, who has the sticks, the sticks."""

from __future__ import annotations

from rich.text import Text
from textual.widgets import Static

from gcs.gamepad.core import PadPhase, PadStatus

GAUGE_CELLS = 7  # odd, so that centre has a cell of its own
PHASE_STYLE = {PadPhase.ENGAGED: "bold green", PadPhase.WAITING: "yellow",
               PadPhase.UNPLUGGED: "bold red"}


def gauge(value: float) -> str:
    """A stick's deflection -1..1 as a short bar with a marker, e.g. '┈┈┈●┈┈┈'."""
    pos = round((max(-1.0, min(1.0, value)) + 1.0) / 2.0 * (GAUGE_CELLS - 1))
    return "".join("●" if i == pos else "┼" if i == GAUGE_CELLS // 2 else "┈"
                   for i in range(GAUGE_CELLS))


def render_pad(name: str, mapping_key: str, status: PadStatus) -> Text:
    """Two lines (77 columns at most, so 80 fit): the pad, its phase, the throttle it sends
    and a note; then the four sticks, mode 2 order (left stick first)."""
    text = Text(no_wrap=True, overflow="ellipsis")
    text.append(f"pad {name} [{mapping_key}] ")
    text.append(status.phase.value, style=PHASE_STYLE[status.phase])
    text.append(f"  {status.throttle_us} µs")
    if status.note:
        text.append(f"  {status.note}", style="yellow")
    text.append("\n")
    text.append("  ".join(f"{label} {gauge(value)} {value:+.2f}" for label, value in (
        ("thr", status.throttle_axis), ("yaw", status.yaw), ("pitch", status.pitch),
        ("roll", status.roll))))
    return text


class PadPanel(Static):
    """Shown only when teleop runs with a gamepad, so the keyboard-only screen is unchanged."""

    DEFAULT_CSS = """
    PadPanel {
        height: 2;
        padding: 0 1;
    }
    """

    def show(self, name: str, mapping_key: str, status: PadStatus) -> None:
        """Redraw from the pad's latest status."""
        self.update(render_pad(name, mapping_key, status))
