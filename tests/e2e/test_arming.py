"""Arming against the SITL as the real firmware answers: refused while its pre-arm checks still
fail after boot (3.2.1: UNSUPPORTED with "PreArm: ...", 4.x: FAILED with "Arm: ..."), so the
station asks again until they pass; a refusal that never clears ends in one line naming the
firmware's reason."""

from __future__ import annotations

from pathlib import Path

import pytest

from firmware_link import LinkError, VehicleLink
from firmware_link.records import FlightMode, RcCommand, StatusText
from gcs import topics
from gcs.cli import build_parser
from gcs.commands.fly import fly
from logs import open_recording
from tests.e2e.fault_flight import ROOT, _sitl

pytestmark = [pytest.mark.e2e, pytest.mark.timeout(240)]


@pytest.mark.parametrize(("profile", "text"), [("apm25", "PreArm: INS not calibrated"),
                                               ("copter4", "Arm: Accels inconsistent")])
def test_arm_right_after_boot_is_retried_until_prearm_passes(profile: str, text: str) -> None:
    with _sitl(["--tcp", "0", "--profile", profile, "--speedup", "2"]) as sitl:
        link = VehicleLink.open("tcp:" + sitl.endpoint(1, "tcp"))
        try:
            link.arm(timeout_s=30.0, retry=True)  # at once: the pre-arm window is still open
            assert link.armed
            said = [r.text for r in link.poll() if isinstance(r, StatusText)]
            assert any(text in t for t in said), said  # it was refused first, and said why
            link.disarm(timeout_s=10.0, retry=True)
        finally:
            link.close()


@pytest.mark.parametrize(("profile", "reason"), [("apm25", "throttle"),
                                                 ("copter4", "Arm: Throttle too high")])
def test_a_refusal_that_never_clears_ends_in_one_line_with_the_reason(
        profile: str, reason: str) -> None:
    # real time: the link's clock is the wall's, and 4.x drops the override after 3 s
    with _sitl(["--tcp", "0", "--profile", profile]) as sitl:
        link = VehicleLink.open("tcp:" + sitl.endpoint(1, "tcp"))
        try:
            link.set_mode(FlightMode.STABILIZE)
            for _ in range(5):  # throttle up: a manual mode refuses to arm
                link.rc_override(RcCommand(1500, 1500, 1600, 1500))
                link.poll()
            with pytest.raises(LinkError) as err:  # within 4.x's 3 s RC_OVERRIDE_TIME
                link.arm(timeout_s=2.5, retry=True)
            line = str(err.value)
            assert "\n" not in line and "refused to arm" in line and reason.lower() in line.lower()
            assert not link.armed
        finally:
            link.close()


def test_fly_on_copter4_with_the_real_pre_arm_delay_arms_once_it_passes(tmp_path: Path) -> None:
    world = tmp_path / "boot.toml"
    world.write_text((ROOT / "worlds" / "empty_room.toml").read_text()
                     + "\n[autopilot]\nrealistic_boot = true\n")
    out = tmp_path / "flight.mcap"
    args = build_parser().parse_args([
        "fly", "--profile", "copter4", "--world", str(world), "--fix-failsafe", "--hold", "2",
        "--speedup", "4", "--seed", "2", "-o", str(out),
        # a loaded machine runs the 4x SITL behind the station's 4x clock: its 24 s of boot
        # took more than the default 30 s of the station's (seen with two test processes)
        "--arm-timeout", "60"])
    summary = fly(args)
    assert summary["status"] == "ok" and summary["dialect"] == "copter4"
    texts = [m["text"] for _t, _ns, m in open_recording(out).messages([topics.STATUS_TEXT])]
    assert any("Arm: Accels inconsistent" in t for t in texts), texts
