"""The link panel's forwarding row: shown only while forwarding, refusals counted."""

from __future__ import annotations

from gcs.pilot.view import LinkView, TeleopView
from gcs.tui.widgets import LinkPanel


def panel_text(link: LinkView) -> str:
    return LinkPanel().render_view(TeleopView(link=link)).plain


def test_the_firmware_and_how_it_was_identified() -> None:
    text = panel_text(LinkView(url="tcp:127.0.0.1:5760", dialect="copter4",
                               firmware="ArduCopter V4.7.0-dev",
                               firmware_source="AUTOPILOT_VERSION"))
    assert text.splitlines()[0] == "tcp:127.0.0.1:5760  ArduCopter V4.7.0-dev · AUTOPILOT_VERSION"
    # a view without it (a replay of an older recording) still names the dialect
    assert panel_text(LinkView(url="x", dialect="apm25")).splitlines()[0] == "x  apm25"


def test_no_forwarding_row_without_forwarding() -> None:
    assert "fwd" not in panel_text(LinkView(url="tcp:127.0.0.1:5760"))


def test_forwarding_row_shows_stations_and_refused_overrides() -> None:
    text = panel_text(LinkView(url="tcp:127.0.0.1:5760", fwd_stations=2,
                               fwd_refused_overrides=17))
    assert "fwd 2 stn" in text and "rc refused 17" in text
