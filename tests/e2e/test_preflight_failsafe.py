"""`quadgcs fly` refuses a vehicle whose failsafe would not land it on a silent link, and flies
it once `--fix-failsafe` has set what is needed.

The bundled SITL serves the real firmware's parameter defaults (4.7: FS_GCS_ENABLE 0,
FS_GCS_TIMEOUT 5, FS_OPTIONS 16, RC_OVERRIDE_TIME 3) and reports GPS_RAW_INT with no fix, which
the station must ask 4.x for: a GPS it never heard of is judged as a fix (RTL would navigate,
and climb to RTL_ALT). Over TCP the SITL runs as its own program and the parameters are set
beforehand by a link of their own, as an owner would have left them.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from firmware_link import VehicleLink
from tests.e2e.fault_flight import ROOT, _sitl
from tests.e2e.sitl_proc import SitlProcess

pytestmark = [pytest.mark.e2e, pytest.mark.timeout(300)]

SPEEDUP = 4.0
FIXED_4X = ("--fix-failsafe: set FS_GCS_ENABLE 0 -> 5, FS_GCS_TIMEOUT 5 -> 2, FS_OPTIONS 16 -> 0 "
            "(read back); FS_GCS_ENABLE 5: on a silent link the vehicle after 2 s holds 4 s, "
            "then lands")


def quadgcs(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "lab", "fly", "--no-record", "--hold", "1",
                           "--seed", "4", *argv], capture_output=True, text=True, timeout=240,
                          cwd=ROOT)


def last_line(proc: subprocess.CompletedProcess[str]) -> str:
    lines = proc.stderr.strip().splitlines()
    assert lines, proc
    return lines[-1]


def test_lockstep_copter4_defaults_are_refused_with_one_line() -> None:
    proc = quadgcs("--lockstep", "--profile", "copter4")
    assert proc.returncode != 0
    line = last_line(proc)
    assert line.startswith("quadgcs fly: arming: vehicle 1: arm refused: FS_GCS_ENABLE 0: on a "
                           "silent link the vehicle keeps flying on the receiver's throttle (no "
                           "GCS failsafe); set FS_GCS_ENABLE 5 or pass --fix-failsafe"), line
    assert "Traceback" not in proc.stderr


def test_lockstep_copter4_with_fix_failsafe_flies_and_says_what_it_set() -> None:
    proc = quadgcs("--lockstep", "--profile", "copter4", "--fix-failsafe")
    assert proc.returncode == 0, proc.stderr
    assert f"vehicle 1: {FIXED_4X}\n" in proc.stderr


def test_lockstep_apm25_without_gps_lands_by_itself_and_needs_no_fix() -> None:
    # 3.2.1 with no GPS fix: its GCS failsafe's RTL is refused and it lands (RTL_ALT unread)
    proc = quadgcs("--lockstep", "--profile", "apm25")
    assert proc.returncode == 0, proc.stderr
    assert "--fix-failsafe:" not in proc.stderr


def test_lockstep_apm25_with_gps_is_refused_then_fixed_to_rtl_at_its_height(
        tmp_path: Path) -> None:
    # 3.2.1 with a GPS fix: its GCS failsafe's RTL climbs to RTL_ALT (15 m) before it returns
    world = tmp_path / "gps.toml"
    world.write_text((ROOT / "worlds" / "empty_room.toml").read_text()
                     + "\n[autopilot]\ngps = true\n")
    refused = quadgcs("--lockstep", "--profile", "apm25", "--world", str(world))
    assert refused.returncode != 0
    line = last_line(refused)
    assert line.startswith("quadgcs fly: arming: vehicle 1: arm refused: RTL_ALT 1500: on a "
                           "silent link the vehicle after 5 s climbs to RTL_ALT 15 m in RTL "
                           "(GPS 3D fix); set RTL_ALT 0 (return at the current height) or pass "
                           "--fix-failsafe"), line
    fixed = quadgcs("--lockstep", "--profile", "apm25", "--world", str(world), "--fix-failsafe")
    assert fixed.returncode == 0, fixed.stderr
    assert "RTL_ALT 1500 -> 0" in fixed.stderr


@pytest.fixture
def copter4_tcp() -> Iterator[SitlProcess]:
    with _sitl(["--tcp", "0", "--profile", "copter4", "--speedup", f"{SPEEDUP:g}",
                "--seed", "4"]) as sitl:
        yield sitl


def _set(sitl: SitlProcess, **values: float) -> None:
    link = VehicleLink.open("tcp:" + sitl.endpoint(1, "tcp"))
    try:
        for name, value in values.items():
            assert link.set_param(name, value) == value
    finally:
        link.close()


def _fly_tcp(sitl: SitlProcess, *argv: str) -> subprocess.CompletedProcess[str]:
    return quadgcs("--connect", "tcp:" + sitl.endpoint(1, "tcp"), "--profile", "copter4",
                   "--speedup", f"{SPEEDUP:g}", *argv)


# a wall-clock flight (4x): beside other wall-clock flights only (make test's `wallclock` pass)
@pytest.mark.wallclock
def test_tcp_copter4_fs_options_16_is_refused_then_fixed(copter4_tcp: SitlProcess) -> None:
    # as the fixture flights had 4.7: the GCS failsafe on and early, FS_OPTIONS its default
    _set(copter4_tcp, FS_GCS_ENABLE=5.0, FS_GCS_TIMEOUT=2.0)
    refused = _fly_tcp(copter4_tcp)
    assert refused.returncode != 0
    assert last_line(refused).startswith(
        "quadgcs fly: arming: vehicle 1: arm refused: FS_OPTIONS 16: on a silent link the "
        "vehicle keeps flying on "
        "the receiver's throttle (bit 4: continue in pilot-controlled modes); set bit 4 off or "
        "pass --fix-failsafe;"), refused.stderr
    flown = _fly_tcp(copter4_tcp, "--fix-failsafe")
    assert flown.returncode == 0, flown.stderr
    assert ("vehicle 1: --fix-failsafe: set FS_OPTIONS 16 -> 0 (read back); FS_GCS_ENABLE 5: on "
            "a silent link the vehicle after 2 s holds 4 s, then lands\n") in flown.stderr
    # what the vehicle holds now, read by a link of its own
    link = VehicleLink.open("tcp:" + copter4_tcp.endpoint(1, "tcp"))
    try:
        assert link.read_params(["FS_OPTIONS", "FS_GCS_ENABLE", "FS_GCS_TIMEOUT"]) == {
            "FS_OPTIONS": 0.0, "FS_GCS_ENABLE": 5.0, "FS_GCS_TIMEOUT": 2.0}
    finally:
        link.close()


@pytest.mark.wallclock
def test_tcp_copter4_rtl_is_judged_by_the_gps_fix_it_reports(copter4_tcp: SitlProcess) -> None:
    # FS_GCS_ENABLE 1 (RTL) climbs to RTL_ALT with a GPS fix and lands without one: the SITL
    # reports no fix, so the station flies only if it asked for GPS_RAW_INT and heard it
    _set(copter4_tcp, FS_GCS_ENABLE=1.0, FS_GCS_TIMEOUT=2.0, FS_OPTIONS=0.0)
    proc = _fly_tcp(copter4_tcp)
    assert proc.returncode == 0, proc.stderr
    assert "climbs" not in proc.stderr and "--fix-failsafe:" not in proc.stderr
