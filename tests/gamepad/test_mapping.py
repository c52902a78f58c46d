"""Gamepad mapping files: the bundled entries, selection by name and type, one-line errors."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from gcs.errors import UsageError
from gcs.gamepad.mapping import AxisSource, ButtonSource, load_mappings


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "pads.toml"
    p.write_text(text)
    return p


GOOD_ENTRY = """
[pads.mine]
match = ["my pad"]
[pads.mine.axes]
roll = "axis0"
pitch = "-axis1"
yaw = "axis2"
throttle = "-axis3"
[pads.mine.buttons]
kill = 0
arm = 3
"""


def test_bundled_entries_cover_the_common_pads() -> None:
    m = load_mappings()
    assert [e.key for e in m.entries] == ["xbox", "dualshock", "f310", "controller", "joystick"]
    xbox = m.entries[0]
    assert xbox.axes["throttle"] == AxisSource("lefty", None, invert=True)
    assert xbox.buttons["kill"] == ButtonSource("b", None)
    assert xbox.settings.poll_hz == 50.0 and xbox.settings.throttle == "accumulate"


@pytest.mark.parametrize(("name", "ctype", "key"), [
    ("Xbox 360 Controller", "xbox360", "xbox"),
    ("Some Pad", "xboxone", "xbox"),
    ("PS4 Controller", "ps4", "dualshock"),
    ("Sony Interactive Entertainment Wireless Controller", "ps4", "dualshock"),
    ("DualSense Wireless Controller", "ps5", "dualshock"),
    ("Logitech Gamepad F310", "xbox360", "f310"),  # its X mode says xbox360: the name wins
    ("Logitech Dual Action", "unknown", "f310"),
    ("8BitDo Pro 2", "switchpro", "controller"),
    ("Generic USB Joystick", None, "joystick"),
])
def test_selection_by_name_then_type_then_fallback(name: str, ctype: str | None,
                                                    key: str) -> None:
    assert load_mappings().select(name, ctype).key == key


def test_a_users_entry_comes_first_and_its_defaults_reach_bundled_pads(tmp_path: Path) -> None:
    path = write(tmp_path, "[defaults]\ndeadzone = 0.02\npoll_hz = 100\n" + GOOD_ENTRY)
    m = load_mappings(path)
    mine = m.select("My Pad v2", None)
    assert mine.key == "mine" and mine.source == str(path)
    assert mine.buttons["arm"] == ButtonSource(None, 3)
    assert m.select("Xbox 360 Controller", "xbox360").settings.deadzone == 0.02
    assert m.select("Xbox 360 Controller", "xbox360").settings.poll_hz == 100.0


def test_per_pad_settings_override_the_defaults(tmp_path: Path) -> None:
    text = GOOD_ENTRY.replace('match = ["my pad"]', 'match = ["my pad"]\nthrottle = "full"')
    mine = load_mappings(write(tmp_path, text)).select("my pad", None)
    assert mine.settings.throttle == "full"


@pytest.mark.parametrize(("change", "message"), [
    (('roll = "axis0"', 'roll = "leftz"'),
     "[pads.mine].axes roll = 'leftz' is not an axis: expected one of lefttrigger"),
    (('roll = "axis0"', 'roll = 3'), "[pads.mine].axes roll = 3: expected an axis name"),
    (("kill = 0", "kill = -1"), "[pads.mine].buttons kill = -1 is out of range"),
    (("kill = 0", "kill = 300"), "[pads.mine].buttons kill = 300 is out of range"),
    (("kill = 0", 'kill = "circle"'), "[pads.mine].buttons kill = 'circle' is not a button"),
    (("kill = 0", "kill = true"), "[pads.mine].buttons kill = True: expected a button"),
    (("kill = 0", "fire = 0"), "[pads.mine].buttons: 'fire' is not a pad action"),
    (("arm = 3", "arm = 3\nkill = 1"), "not valid TOML"),
    (('yaw = "axis2"\n', ""), "[pads.mine]: 'yaw' is not mapped"),
    (('match = ["my pad"]', 'match = "my pad"'), "[pads.mine] match: expected a list"),
    (('match = ["my pad"]', 'match = ["x"]\ntypes = ["xbox"]'),
     "types: 'xbox' is not an SDL controller type"),
    (('match = ["my pad"]', 'match = ["x"]\nexpo = 2'), "expo = 2 is out of range (0..1)"),
    (('match = ["my pad"]', 'match = ["x"]\nthrottle = "half"'), "throttle = 'half'; expected"),
    (('match = ["my pad"]', 'match = ["x"]\npoll_hz = 0'), "poll_hz = 0 must be positive"),
    (('match = ["my pad"]', 'match = ["x"]\ncolour = 1'), "unknown key 'colour'"),
])
def test_a_bad_file_is_one_line_naming_the_key(tmp_path: Path, change: tuple[str, str],
                                                message: str) -> None:
    old, new = change
    assert old in GOOD_ENTRY
    path = write(tmp_path, GOOD_ENTRY.replace(old, new, 1))
    with pytest.raises(UsageError) as exc:
        load_mappings(path)
    text = str(exc.value)
    assert message in text and "\n" not in text
    assert str(path) in text


def test_a_missing_file_is_one_line(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match=r"gamepad map .*nope.toml: no such file"):
        load_mappings(tmp_path / "nope.toml")


def test_a_raw_index_is_checked_against_the_pad(tmp_path: Path) -> None:
    mine = load_mappings(write(tmp_path, GOOD_ENTRY.replace("arm = 3", "arm = 12"))).entries[0]
    mine.check_against("My Pad", False, n_axes=4, n_buttons=13)
    with pytest.raises(UsageError, match=r"button 'arm' = 12 is out of range: 'My Pad' has 12 "
                                         r"buttons \(0..11\)"):
        mine.check_against("My Pad", False, n_axes=4, n_buttons=12)
    with pytest.raises(UsageError, match=r"axis 'throttle' = axis3 is out of range"):
        mine.check_against("My Pad", False, n_axes=3, n_buttons=12)


def test_controller_names_need_a_pad_in_sdls_database() -> None:
    xbox = load_mappings().entries[0]
    with pytest.raises(UsageError, match="is not in SDL's controller database"):
        xbox.check_against("Odd Stick", False, n_axes=6, n_buttons=15)


@pytest.mark.parametrize(("text", "message"), [
    ("defaults = 3\n", "[defaults] must be a table"),
    ("[defaults]\ndeadzone = 1.0\n", "deadzone = 1.0 is out of range"),
    ("[colours]\n", "unknown table 'colours'"),
    ("pads = 1\n", "[pads] must hold tables"),
])
def test_a_bad_defaults_or_top_level_table_is_one_line(tmp_path: Path, text: str,
                                                       message: str) -> None:
    with pytest.raises(UsageError, match=re.escape(message)):
        load_mappings(write(tmp_path, text))
