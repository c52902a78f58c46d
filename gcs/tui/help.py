"""The help screen: every key binding, generated from the app's own bindings."""

from __future__ import annotations

from typing import ClassVar

from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import Static

KEY_NAMES = {"question_mark": "?", "plus": "+", "minus": "-", "space": "space"}


def describe(bindings: list[BindingType]) -> str:
    """One line per binding: keys, then what they do."""
    rows = []
    for b in bindings:
        if isinstance(b, Binding):
            keys, desc = b.key, b.description
        else:
            keys, desc = b[0], b[2] if len(b) > 2 else b[1]
        names = [KEY_NAMES.get(k, k) for k in keys.split(",")]
        rows.append(f"  {' / '.join(names):<22} {desc}")
    return "\n".join(rows)


class HelpScreen(ModalScreen[None]):
    """Lists every binding; any key closes it."""

    BINDINGS: ClassVar[list[BindingType]] = [
        ("escape,question_mark,q", "dismiss", "Close help")
    ]

    def __init__(self, text: str) -> None:
        super().__init__()
        self._text = text

    def compose(self) -> ComposeResult:
        """A single bordered box of text."""
        with Vertical(id="help-box"):
            yield Static("Key bindings", id="help-title")
            yield Static(self._text, id="help-body")
            yield Static("Press Esc or ? to close.", id="help-foot")


class ConfirmQuit(ModalScreen[bool]):
    """Quitting with the vehicle armed: say what will happen, and ask."""

    BINDINGS: ClassVar[list[BindingType]] = [
        ("y", "answer(True)", "Land and quit"),
        ("n,escape", "answer(False)", "Stay"),
    ]

    def compose(self) -> ComposeResult:
        """One bordered question."""
        with Vertical(id="help-box"):
            yield Static("The vehicle is ARMED", id="help-title")
            yield Static("Quitting lands it first (LAND mode, confirmed by its heartbeat),\n"
                         "then hands the sticks back. A lost link leaves it to its own failsafe.",
                         id="help-body")
            yield Static("y: land and quit    n / Esc: stay", id="help-foot")

    def action_answer(self, quit_: bool) -> None:
        """Close with the pilot's answer."""
        self.dismiss(quit_)
