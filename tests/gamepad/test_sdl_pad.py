"""SDL at the edge, against SDL's virtual joystick: the same SDL joystick API as a real pad."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from gcs.cli import build_parser, main
from gcs.commands.teleop import open_gamepad
from gcs.errors import RuntimeFault, UsageError
from gcs.gamepad.mapping import load_mappings
from gcs.gamepad.sdl_pad import SdlPad, init_sdl, list_pads, quit_sdl
from tests.gamepad.virtual_pad import F310, VirtualPad


@pytest.fixture
def xbox() -> Iterator[VirtualPad]:
    pad = VirtualPad()
    yield pad
    pad.close()


@pytest.fixture
def raw_stick() -> Iterator[VirtualPad]:
    pad = VirtualPad("Generic USB Joystick", vendor_id=0, product_id=0, controller=False,
                     n_axes=4, n_buttons=8)
    yield pad
    pad.close()


def test_reads_sticks_and_buttons_by_role(xbox: VirtualPad) -> None:
    pad = SdlPad(None, load_mappings())
    try:
        assert pad.name == "Xbox 360 Controller" and pad.mapping.key == "xbox"
        sample = pad.read()
        assert sample is not None and sample.buttons == frozenset()
        assert sample.axes == {"roll": 0.0, "pitch": 0.0, "yaw": 0.0, "throttle": 0.0}
        xbox.axis("lefty", -1.0)  # left stick pushed up
        xbox.axis("righty", 0.5)  # right stick half back
        xbox.axis("rightx", 0.25)
        xbox.button("start", True)
        xbox.button("b", True)
        sample = pad.read()
        assert sample is not None
        assert sample.axes["throttle"] == pytest.approx(1.0, abs=1e-4)
        assert sample.axes["pitch"] == pytest.approx(-0.5, abs=1e-4)
        assert sample.axes["roll"] == pytest.approx(0.25, abs=1e-4)
        assert sample.buttons == {"arm", "kill"}
    finally:
        pad.close()


def test_unplug_reads_none_and_a_replug_is_reopened(xbox: VirtualPad) -> None:
    pad = SdlPad("xbox", load_mappings(), poll_hz=20.0)
    try:
        assert pad.settings.poll_hz == 20.0
        xbox.unplug()
        assert pad.read() is None and not pad.connected
        assert pad.read() is None
        xbox.plug()
        xbox.button("a", True)
        sample = pad.read()
        assert pad.connected and sample is not None and sample.buttons == {"hold"}
    finally:
        pad.close()


def test_choose_by_index_and_by_name(xbox: VirtualPad) -> None:
    f310 = VirtualPad(F310["name"], vendor_id=0, product_id=0)
    try:
        by_name = SdlPad("F310", load_mappings())
        assert by_name.name == F310["name"] and by_name.mapping.key == "f310"
        by_name.close()
        sdl = init_sdl()
        index = next(p.index for p in list_pads(sdl) if p.name == F310["name"])
        quit_sdl(sdl)
        by_index = SdlPad(str(index), load_mappings())
        assert by_index.name == F310["name"]
        by_index.close()
        with pytest.raises(RuntimeFault, match=r"no pad named like 'dualshock' \(connected: "
                                               r".*Xbox 360 Controller, .*Logitech"):
            SdlPad("dualshock", load_mappings())
        with pytest.raises(RuntimeFault, match="no pad at index 99"):
            SdlPad("99", load_mappings())
    finally:
        f310.close()


def test_no_pad_at_all() -> None:
    sdl = init_sdl()
    real = list_pads(sdl)
    quit_sdl(sdl)
    if real:
        pytest.skip(f"a pad is plugged into this machine: {real[0].name}")
    with pytest.raises(RuntimeFault, match="gamepad: no pad connected"):
        SdlPad(None, load_mappings())


def test_a_pad_outside_sdls_database_uses_raw_indices(raw_stick: VirtualPad,
                                                      tmp_path: Path) -> None:
    # the bundled [pads.joystick] wants button 9: this stick has 8
    with pytest.raises(UsageError, match=r"button 'arm' = 9 is out of range: 'Generic USB "
                                         r"Joystick' has 8 buttons \(0..7\)"):
        SdlPad(None, load_mappings())
    mine = tmp_path / "mine.toml"
    mine.write_text('[pads.mine]\nmatch = ["generic usb"]\n'
                    '[pads.mine.axes]\nroll = "axis2"\npitch = "-axis3"\nyaw = "axis0"\n'
                    'throttle = "-axis1"\n[pads.mine.buttons]\nkill = 1\narm = 7\n')
    pad = SdlPad(None, load_mappings(mine))
    try:
        raw_stick.axis(1, -0.5)
        raw_stick.button(7, True)
        sample = pad.read()
        assert sample is not None and sample.buttons == {"arm"}
        assert sample.axes["throttle"] == pytest.approx(0.5, abs=1e-4)
    finally:
        pad.close()


def test_cli_bad_axis_name_is_one_line_exit_2(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[pads.x]\n[pads.x.axes]\nroll = "leftz"\n')
    assert main(["teleop", "--gamepad", "--gamepad-map", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("quadgcs teleop: ")
    assert "roll = 'leftz' is not an axis" in err and str(bad) in err


def test_cli_button_out_of_range_is_one_line_exit_2(raw_stick: VirtualPad, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[pads.mine]\nmatch = ["generic"]\n[pads.mine.axes]\nroll = "axis0"\n'
                   'pitch = "axis1"\nyaw = "axis2"\nthrottle = "axis3"\n'
                   '[pads.mine.buttons]\nkill = 12\n')
    assert main(["teleop", "--gamepad", "generic", "--gamepad-map", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err == ("quadgcs teleop: gamepad mapping 'mine' (" + str(bad) + "): button 'kill' = "
                   "12 is out of range: 'Generic USB Joystick' has 8 buttons (0..7)\n")


def test_cli_gamepad_flags_need_gamepad(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["teleop", "--gamepad-rate", "30"]) == 2
    assert "--gamepad-map and --gamepad-rate need --gamepad" in capsys.readouterr().err
    assert main(["teleop", "--gamepad", "--gamepad-rate", "0"]) == 2
    assert "--gamepad-rate 0: expected 0 < HZ <= 250" in capsys.readouterr().err


def test_teleop_opens_the_pad_the_flags_name(xbox: VirtualPad) -> None:
    args = build_parser().parse_args(["teleop", "--gamepad", "xbox", "--gamepad-rate", "25"])
    gamepad = open_gamepad(args)
    assert gamepad is not None
    try:
        assert gamepad.name == "Xbox 360 Controller" and gamepad.poll_hz == 25.0
        assert gamepad.source.mapping.key == "xbox"
    finally:
        gamepad.close()
    assert open_gamepad(build_parser().parse_args(["teleop"])) is None


def test_a_pad_is_found_by_sdls_controller_type() -> None:
    # a name no entry matches, but Sony's DualShock 4 ids: SDL's database says ps4
    ds4 = VirtualPad("Gamepad 7", vendor_id=0x054C, product_id=0x09CC)
    try:
        pad = SdlPad(None, load_mappings())
        assert pad.mapping.key == "dualshock"
        pad.close()
    finally:
        ds4.close()
