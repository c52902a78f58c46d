"""tlog import/export against the real ArduCopter 4.7 SITL flight, read back by pymavlink."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

from gcs.cli import main
from logs import RecordingError, open_recording
from logs.tlog import export_tlog, read_tlog

REPO = Path(__file__).resolve().parents[2]


def _pymavlink_digests(*paths: Path) -> list[dict]:
    """Digest each tlog with pymavlink, in parallel child processes."""
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "tests.logs.pymavlink_dump", str(path)],
            cwd=REPO,
            stdout=subprocess.PIPE,
            text=True,
        )
        for path in paths
    ]
    out = []
    for proc in procs:
        stdout, _ = proc.communicate(timeout=180)
        assert proc.returncode == 0
        out.append(json.loads(stdout))
    return out


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory) -> tuple[Path, Path, Path]:
    from tests.logs.conftest import FLIGHT_TLOG

    if not FLIGHT_TLOG.exists():
        pytest.skip(f"the real 4.7 flight log {FLIGHT_TLOG} is not here "
                    "(it comes with ../shared/fixtures)")
    d = tmp_path_factory.mktemp("tlog")
    mcap = d / "imported.mcap"
    out = d / "exported.tlog"
    assert main(["logs", "import-tlog", str(FLIGHT_TLOG), "-o", str(mcap)]) == 0
    assert main(["logs", "export", str(mcap), "--tlog", str(out)]) == 0
    return FLIGHT_TLOG, mcap, out


def test_import_splits_directions_by_gcs_sysid(round_trip) -> None:
    src, mcap, _ = round_trip
    rec = open_recording(mcap)
    frames = list(read_tlog(src))
    tx = sum(1 for f in frames if f.sysid == 255)
    assert rec.counts == {"/mavlink/rx": len(frames) - tx, "/mavlink/tx": tx}
    assert rec.counts == {"/mavlink/rx": 74094, "/mavlink/tx": 8521}  # as ECOSYSTEM.md measured
    assert rec.duration_s == pytest.approx(257.06, abs=0.01)
    assert rec.metadata["imported_from"] == src.name


def test_export_is_byte_identical_to_the_source(round_trip) -> None:
    src, _, out = round_trip
    assert out.read_bytes() == src.read_bytes()


def test_pymavlink_reads_the_export_frame_for_frame(round_trip) -> None:
    """pymavlink decodes every exported frame, at the source's timestamps, in the source's order."""
    src, _, out = round_trip
    (got,) = _pymavlink_digests(out)
    source_frames = list(read_tlog(src))
    assert got["count"] == len(source_frames) == 82_615
    stamps = hashlib.sha256()
    for frame in source_frames:
        stamps.update(f"{frame.t_us}|".encode())
    assert got["stamps_sha256"] == stamps.hexdigest()
    assert {"HEARTBEAT", "ATTITUDE", "RC_CHANNELS_OVERRIDE"} <= set(got["types"])


def test_export_of_a_live_recording_keeps_time_order(recorded_flight, tmp_path) -> None:
    path, counts = recorded_flight
    n = export_tlog(open_recording(path), tmp_path / "live.tlog")
    assert n == counts["/mavlink/rx"] + counts["/mavlink/tx"]
    frames = list(read_tlog(tmp_path / "live.tlog"))
    assert len(frames) == n
    stamps = [f.t_us for f in frames]
    assert stamps == sorted(stamps)
    assert {f.sysid for f in frames} == {1, 255}


def test_torn_last_frame_is_left_out_and_garbage_is_an_error(flight_tlog, tmp_path) -> None:
    data = flight_tlog.read_bytes()
    torn = tmp_path / "torn.tlog"
    torn.write_bytes(data[:1000])
    frames = list(read_tlog(torn))
    assert 0 < len(frames) < 50
    assert all(f.data[0] == 0xFD for f in frames)
    bad = tmp_path / "bad.tlog"
    bad.write_bytes(b"\x00" * 8 + b"hello world, not mavlink")
    with pytest.raises(RecordingError, match="not a tlog"):
        list(read_tlog(bad))


def test_export_without_raw_frames_is_refused(tmp_path) -> None:
    from logs import Recorder

    with Recorder(tmp_path / "r.mcap", metadata={}) as rec:
        rec.put("/x", 1.0, {"a": 1})
    with pytest.raises(RecordingError, match="no raw MAVLink frames"):
        export_tlog(open_recording(rec.path), tmp_path / "x.tlog")


def test_mavlink1_and_signed_mavlink2_frames_are_delimited(tmp_path) -> None:
    """APM 2.5 speaks MAVLink 1 (0xFE); a signed MAVLink 2 frame carries 13 more bytes."""
    v1 = bytes([0xFE, 3, 7, 1, 1, 0]) + b"abc" + b"\x11\x22"
    v1_gcs = bytes([0xFE, 2, 8, 255, 190, 70]) + b"xy" + b"\x33\x44"
    v2_signed = bytes([0xFD, 4, 0x01, 0, 9, 1, 1, 30, 0, 0]) + b"wxyz" + b"\x55\x66" + bytes(13)
    v2 = bytes([0xFD, 1, 0, 0, 10, 255, 190, 70, 0, 0]) + b"q" + b"\x77\x88"
    stamps = [1_700_000_000_000_000 + 25_000 * i for i in range(4)]
    tlog = tmp_path / "mixed.tlog"
    sent = (v1, v1_gcs, v2_signed, v2)
    tlog.write_bytes(b"".join(t.to_bytes(8, "big") + f for t, f in zip(stamps, sent, strict=True)))
    frames = list(read_tlog(tlog))
    assert [f.data for f in frames] == list(sent)
    assert [f.sysid for f in frames] == [1, 255, 1, 255]
    assert [f.t_us for f in frames] == stamps
    mcap = tmp_path / "mixed.mcap"
    assert main(["logs", "import-tlog", str(tlog), "-o", str(mcap)]) == 0
    assert open_recording(mcap).counts == {"/mavlink/rx": 2, "/mavlink/tx": 2}
    assert export_tlog(open_recording(mcap), tmp_path / "back.tlog") == 4
    assert (tmp_path / "back.tlog").read_bytes() == tlog.read_bytes()
