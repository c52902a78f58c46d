"""`quadgcs params` as a pilot runs it against the bundled SITL over TCP, in both profiles, and
the link's firmware identification against the same SITL."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from firmware_link import VehicleLink, format_param_value, read_parm_file
from firmware_link.records import Dialect
from tests.e2e.sitl_proc import SitlProcess

pytestmark = pytest.mark.e2e
ROOT = Path(__file__).resolve().parents[2]


def quadgcs(*argv: str, timeout_s: float = 120.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "gcs", "params", *argv], capture_output=True,
                          text=True, timeout=timeout_s, cwd=ROOT)


def one_line_error(proc: subprocess.CompletedProcess[str], code: int, needle: str) -> None:
    assert proc.returncode == code, (proc.stdout, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("quadgcs params:"), proc.stderr
    assert needle in lines[0], lines[0]


@pytest.fixture(scope="module", params=["apm25", "copter4"])
def sitl(request: pytest.FixtureRequest) -> Iterator[tuple[str, str]]:
    # 4x: 3.2.1 sends its 412 parameters at about 25 a second of its own time
    proc = SitlProcess(["--tcp", "0", "--profile", request.param, "--speedup", "4"], ROOT)
    try:
        yield request.param, "tcp:" + proc.endpoint(1, "tcp")
    finally:
        proc.stop()


def test_save_change_load_diff_round_trip(sitl: tuple[str, str], tmp_path: Path) -> None:
    profile, url = sitl
    saved = tmp_path / "vehicle.parm"
    proc = quadgcs("--connect", url, "save", str(saved))
    assert proc.returncode == 0, proc.stderr
    params = read_parm_file(saved)
    assert f"saved {len(params)} parameters of vehicle 1" in proc.stdout
    first = saved.read_text().splitlines()[0]
    # the download brought the version banner both firmwares send first: the exact version
    assert first.startswith("# ArduCopter V") and f"dialect {profile.upper()}" in first
    # an integer parameter and a float one, with names both firmwares share or mirror
    accel = "THR_ACCEL_P" if profile == "apm25" else "PSC_ACCZ_P"
    angle, gain = params["ANGLE_MAX"], params[accel]
    a_old, a_new = format_param_value(angle), format_param_value(angle - 500)
    g_old, g_new = format_param_value(gain), format_param_value(gain + 0.25)

    proc = quadgcs("--connect", url, "get", accel.lower())
    assert (proc.returncode, proc.stdout) == (0, f"{accel} {g_old}\n"), proc.stderr
    proc = quadgcs("--connect", url, "set", accel, g_new)
    assert (proc.returncode, proc.stdout) == (0, f"{accel} {g_old} → {g_new}\n"), proc.stderr
    proc = quadgcs("set", "ANGLE_MAX", a_new, "--connect", url)  # flags after the action
    assert (proc.returncode, proc.stdout) == (0, f"ANGLE_MAX {a_old} → {a_new}\n"), proc.stderr
    one_line_error(quadgcs("--connect", url, "set", "ANGLE_MAX", "12.5"), 2, "whole number")

    proc = quadgcs("--connect", url, "diff", str(saved))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == sorted(
        [f"ANGLE_MAX {a_new} (file {a_old})", f"{accel} {g_new} (file {g_old})"])

    proc = quadgcs("--connect", url, "load", str(saved))
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout.splitlines()
    assert out[:2] == sorted([f"ANGLE_MAX {a_new} → {a_old}", f"{accel} {g_new} → {g_old}"])
    assert out[-1] == (f"loaded {saved}: 2 changed, {len(params) - 2} unchanged, 0 failed "
                       f"of {len(params)}")

    proc = quadgcs("--connect", url, "diff", str(saved))
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "", "")

    proc = quadgcs("--connect", url, "show", "ANGLE_*")
    assert proc.returncode == 0 and proc.stdout.splitlines() == [f"ANGLE_MAX {a_old}"]
    proc = quadgcs("--connect", url, "show")
    names = [line.split()[0] for line in proc.stdout.splitlines()]
    assert names == sorted(params) and len(names) == len(params)


def test_names_the_vehicle_does_not_have(sitl: tuple[str, str]) -> None:
    profile, url = sitl
    one_line_error(quadgcs("--connect", url, "get", "NOPE"), 2, "has no parameter NOPE")
    other = "MOT_THST_HOVER" if profile == "apm25" else "THR_MID"
    hint = "THR_MID" if profile == "apm25" else "MOT_THST_HOVER"
    one_line_error(quadgcs("--connect", url, "set", other, "1"), 2, f"did you mean {hint}")
    one_line_error(quadgcs("--connect", url, "show", "NOPE*"), 1, "no parameter of vehicle 1")


def test_load_refuses_a_file_with_any_bad_line_and_writes_none(
        sitl: tuple[str, str], tmp_path: Path) -> None:
    _, url = sitl
    with VehicleLink.open(url) as link:
        before = link.fetch_params()
    angle = before["ANGLE_MAX"]
    parm = tmp_path / "partial.parm"
    # a valid change first (the old load wrote it before meeting the bad lines), then an
    # unknown name, a fraction for an integer and a value no 8-bit integer holds
    parm.write_text(f"ANGLE_MAX,{format_param_value(angle - 500)}\n"
                    "NOT_A_PARAM 1\nRC1_DZ 2.5\nFS_GCS_ENABLE 70000\n")
    proc = quadgcs("--connect", url, "load", str(parm))
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    assert proc.stdout == ""
    errors = proc.stderr.strip().splitlines()
    assert errors[-1] == (f"quadgcs params: load {parm}: 3 of 4 lines refused; "
                          "nothing was written to the vehicle")
    refused = [e.removeprefix(f"quadgcs params: load {parm}: refused ") for e in errors[:-1]]
    assert [r.split(":")[0] for r in refused] == [
        "NOT_A_PARAM 1", "RC1_DZ 2.5", "FS_GCS_ENABLE 70000"], errors
    assert "unknown name" in refused[0]
    assert "wrong type" in refused[1] and "whole number" in refused[1]
    assert "out of range" in refused[2]
    with VehicleLink.open(url) as link:
        assert link.fetch_params() == before  # read back: not one value changed


def test_the_link_identifies_the_sitl(sitl: tuple[str, str]) -> None:
    profile, url = sitl
    with VehicleLink.open(url) as link:
        fw = link.firmware
        assert fw.dialect is (Dialect.APM25 if profile == "apm25" else Dialect.COPTER4)
        assert fw.evidence and "\n" not in fw.summary
        assert link.get_param(fw.gcs_sysid_param) == 255.0  # the name it found is the real one


@pytest.mark.parametrize(
    ("argv", "code", "needle"),
    [
        (["get", "BAD NAME!"], 2, "parameter name 'BAD NAME!'"),
        (["get", "A_NAME_THAT_IS_TOO_LONG"], 2, "1..16 ASCII"),
        (["--connect", "tcp:127.0.0.1:1", "set", "ANGLE_MAX", "x"], 2, "'x' is not a number"),
        (["--connect", "tcp:127.0.0.1:1", "set", "ANGLE_MAX", "inf"], 2, "not a finite number"),
        (["load", "no/such/file.parm"], 2, "no/such/file.parm: no such file"),
        (["save", "no/such/dir/x.parm"], 2, "no such directory"),
        (["--connect", "tcp:127.0.0.1:1", "--connect-timeout", "0.3", "show"], 1,
         "connection refused"),
        (["--connect", "bogus::url", "show"], 2, "bogus"),
        ([], 2, "expected an action"),
    ],
)
def test_bad_input_ends_in_one_line(argv: list[str], code: int, needle: str) -> None:
    one_line_error(quadgcs(*argv, timeout_s=60.0), code, needle)


def test_a_malformed_file_is_refused_before_any_vehicle(tmp_path: Path) -> None:
    bad = tmp_path / "bad.parm"
    bad.write_text("LAND_SPEED 50\nANGLE_MAX\n")
    one_line_error(quadgcs("--connect", "tcp:127.0.0.1:1", "diff", str(bad)), 2,
                   f"{bad}:2: 'ANGLE_MAX': expected NAME VALUE or NAME,VALUE")


def test_bundled_sitl_by_default() -> None:
    proc = quadgcs("--profile", "copter4", "get", "ANGLE_MAX")
    assert proc.returncode == 0 and proc.stdout.startswith("ANGLE_MAX "), proc.stderr
