"""`quadgcs sitl` passes its flags on to `python -m sitl`, which understands them."""

from __future__ import annotations

import pytest

from gcs.cli import build_parser
from gcs.commands.sitl import sitl_argv
from sitl.cli import build_parser as sitl_parser


def _forwarded(*flags: str) -> list[str]:
    args = build_parser().parse_args(["sitl", *flags])
    argv = sitl_argv(args)
    assert argv[1:3] == ["-m", "sitl"]
    return argv[3:]


def test_the_failsafe_world_flags_reach_the_sitl() -> None:
    argv = _forwarded("--rc-input", "absent", "--gps", "--home-distance", "1.5")
    got = sitl_parser().parse_args(argv)
    assert got.rc_input == "absent" and got.gps is True and got.home_distance == 1.5


@pytest.mark.parametrize(("flag", "gps"), [("--gps", True), ("--no-gps", False)])
def test_gps_on_and_off_both_reach_it(flag: str, gps: bool) -> None:
    assert sitl_parser().parse_args(_forwarded(flag)).gps is gps


def test_a_flag_not_given_is_not_passed_on() -> None:
    argv = _forwarded()
    assert not {"--rc-input", "--gps", "--no-gps", "--home-distance"} & set(argv)
    got = sitl_parser().parse_args(argv)
    assert got.rc_input is None and got.gps is None and got.home_distance is None
