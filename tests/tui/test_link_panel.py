"""The link panel's forwarding row: shown only while forwarding, refusals counted."""

from __future__ import annotations

from gcs.pilot.view import LinkView, TeleopView
from gcs.tui.widgets import LinkPanel


def panel_text(link: LinkView) -> str:
    return LinkPanel().render_view(TeleopView(link=link)).plain


def test_no_forwarding_row_without_forwarding() -> None:
    assert "fwd" not in panel_text(LinkView(url="tcp:127.0.0.1:5760"))


def test_forwarding_row_shows_stations_and_refused_overrides() -> None:
    text = panel_text(LinkView(url="tcp:127.0.0.1:5760", fwd_stations=2,
                               fwd_refused_overrides=17))
    assert "fwd 2 stn" in text and "rc refused 17" in text
