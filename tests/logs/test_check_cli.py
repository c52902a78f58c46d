"""`quadgcs logs check` as a user runs it: tables, JSON, HTML, thresholds files, exit codes, and
the real ArduCopter tlogs no one here wrote (directly and through `logs import-tlog`)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from lab.cli import main
from tests.fixture_paths import FIXTURES

TLOGS = [FIXTURES / "arducopter-3.2.1-sitl-flight.tlog",
         FIXTURES / "arducopter-4.7dev-sitl-flight.tlog"]


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["logs", "check", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_clean_flight_exits_0_with_a_row_per_check(clean_flight: Path,
                                                     capsys: pytest.CaptureFixture[str],
                                                     tmp_path: Path) -> None:
    html = tmp_path / "review.html"
    code, out, _ = _run(capsys, str(clean_flight), "--html", str(html))
    assert code == 0
    assert out.splitlines()[0] == f"{clean_flight}: PASS"
    for key in ("link.loss_pct", "loop.overruns_pct", "vibration.acc_rms_z_mps2",
                "control.stick_limit_pct", "power.sag_v_per_a", "events.failsafes",
                "hold.rms_m"):
        assert any(key in line and line.strip().startswith("PASS") for line in out.splitlines())
    page = html.read_text(encoding="utf-8")
    assert page.count("<svg") == 8 and "hold.rms_m" in page and "why" not in page[:0]


def test_json_and_a_thresholds_file_that_makes_the_hold_fail(clean_flight: Path,
                                                             capsys: pytest.CaptureFixture[str],
                                                             tmp_path: Path) -> None:
    strict = tmp_path / "strict.toml"
    strict.write_text('["hold.rms_m"]\nwarn = 0.001\nfail = 0.002\n', encoding="utf-8")
    code, out, _ = _run(capsys, str(clean_flight), "--json", "--thresholds", str(strict))
    assert code == 1
    report = json.loads(out)
    assert report["status"] == "FAIL"
    rows = {c["check"]: c for c in report["files"][0]["checks"]}
    assert rows["hold.rms_m"]["status"] == "FAIL" and rows["hold.rms_m"]["fail"] == 0.002
    assert rows["hold.rms_m"]["source"] == "truth" and rows["hold.rms_m"]["why"]


def test_bad_input_is_one_line_and_exit_2(clean_flight: Path,
                                          capsys: pytest.CaptureFixture[str],
                                          tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('["loop.jitter_p99_ms"]\nfail = "high"\n', encoding="utf-8")
    code, out, err = _run(capsys, str(clean_flight), "--thresholds", str(bad))
    assert code == 2 and not out
    assert len(err.strip().splitlines()) == 1
    assert str(bad) in err and "loop.jitter_p99_ms" in err and "expected a finite number" in err
    code, _, err = _run(capsys, str(tmp_path / "nope.mcap"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "no such file" in err
    junk = tmp_path / "junk.tlog"
    junk.write_bytes(b"\x00" * 8 + b"garbage!" * 4)
    code, _, err = _run(capsys, str(junk))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "not a tlog" in err
    code, _, err = _run(capsys, str(clean_flight), "--against", str(tmp_path))
    assert code == 2 and "results.parquet" in err


@pytest.mark.parametrize("tlog", TLOGS, ids=lambda p: p.name.split("-sitl")[0])
def test_the_real_firmware_tlogs_are_checked_directly_and_imported(
        tlog: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    if not tlog.exists():
        pytest.skip(f"{tlog} is not here (it comes with ../shared/fixtures)")
    code, out, _ = _run(capsys, str(tlog), "--json")
    direct = {c["check"]: c for c in json.loads(out)["files"][0]["checks"]}
    # flown cleanly by another ground station: nothing fails; what only our station records
    # (its loop, estimator, hold) is SKIP, never a made-up PASS
    assert code == 0
    assert direct["loop.jitter_p99_ms"]["status"] == "SKIP"
    assert direct["hold.rms_m"]["status"] == "SKIP"
    assert direct["link.loss_pct"]["status"] == "PASS" and direct["link.loss_pct"]["value"] == 0
    assert direct["vibration.acc_rms_z_mps2"]["status"] == "PASS"
    assert direct["power.min_cell_v"]["status"] == "PASS"
    assert direct["events.failsafes"]["value"] == 0
    if "3.2.1" in tlog.name:
        # its SET_MODE by MAV_CMD_DO_SET_MODE is refused (UNSUPPORTED) and never accepted
        assert direct["events.refusals"]["status"] == "WARN"
        assert "176" in direct["events.refusals"]["detail"]
        assert direct["link.stream_rate_pct"]["value"] == pytest.approx(66, abs=2)
    mcap = tmp_path / "imported.mcap"
    assert main(["logs", "import-tlog", str(tlog), "-o", str(mcap)]) == 0
    capsys.readouterr()
    code, out, _ = _run(capsys, str(mcap), "--json")
    imported = {c["check"]: c for c in json.loads(out)["files"][0]["checks"]}
    assert code == 0
    assert {k: (c["status"], c["value"]) for k, c in imported.items()} == \
        {k: (c["status"], c["value"]) for k, c in direct.items()}


def test_a_recording_cut_short_by_a_killed_station_is_checked_from_its_whole_chunks(
        clean_flight: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    data = clean_flight.read_bytes()
    cut = tmp_path / "killed.mcap"
    cut.write_bytes(data[: len(data) * 6 // 10])  # no summary, no index, a torn last chunk
    code, out, _ = _run(capsys, str(cut), "--json")
    assert code in (0, 1)
    rows = {c["check"]: c for c in json.loads(out)["files"][0]["checks"]}
    assert rows["link.loss_pct"]["status"] == "PASS"
    assert rows["loop.overruns_pct"]["status"] == "PASS"


@pytest.mark.parametrize(("name", "said"), [
    # the uplink dropped for 15 s in a hold: 3.2.1's GCS failsafe picks RTL at T0 + 5.07 s …
    ("arducopter-3.2.1-uplink-fade.tlog", "RTL at 40.1 s unasked"),
    # … 4.7 (FS_OPTIONS 16) continues in STABILIZE and says so
    ("arducopter-4.7dev-uplink-fade.tlog", "GCS Failsafe - Continuing Pilot Control"),
    # heartbeats stopped for 10 s at the end: 3.2.1 goes to RTL, 4.7 disarms on the floor
    ("arducopter-3.2.1-althold-steps.tlog", "RTL at 103.1 s unasked"),
    ("arducopter-4.7dev-althold-steps.tlog", "GCS Failsafe - Disarming"),
])
def test_the_real_firmwares_failsafes_fail_the_events(
        name: str, said: str, capsys: pytest.CaptureFixture[str]) -> None:
    """The fixtures' failsafes (their README tells when and how each acted) are found."""
    tlog = FIXTURES / name
    if not tlog.exists():
        pytest.skip(f"{tlog} is not here (it comes with ../shared/fixtures)")
    code, out, _ = _run(capsys, str(tlog), "--json")
    rows = {c["check"]: c for c in json.loads(out)["files"][0]["checks"]}
    assert code == 1
    assert rows["events.failsafes"]["status"] == "FAIL" and rows["events.failsafes"]["value"] == 1
    assert said in rows["events.failsafes"]["detail"]
    failed = {k for k, c in rows.items() if c["status"] == "FAIL"}
    assert failed == {"events.failsafes"}
