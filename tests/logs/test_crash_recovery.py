"""A recorder killed with SIGKILL loses at most its last second; recovery keeps the rest."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest

from gcs.cli import main
from logs import RecordingError, open_recording
from logs.recover import recover

REPO = Path(__file__).resolve().parents[2]


def _flushed_span_s(path: Path) -> float:
    if not path.exists() or path.stat().st_size < 16:
        return 0.0
    try:
        rec = open_recording(path, allow_truncated=True)
    except RecordingError:
        return 0.0
    return rec.duration_s if rec.counts.get("/tick") else 0.0


def test_sigkill_mid_recording_loses_at_most_the_last_second(tmp_path: Path, capsys) -> None:
    path = tmp_path / "killed.mcap"
    child = subprocess.Popen(
        [sys.executable, "-m", "tests.logs.crash_child", str(path)],
        cwd=REPO,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(REPO)},
    )
    seen: list[str] = []
    try:
        assert child.stdout is not None
        # each tick the child prints is a moment to look at the file: 3 flushed seconds on disk
        for line in child.stdout:
            seen.append(line)
            if len(seen) % 20 == 0 and _flushed_span_s(path) >= 3.0:
                break
            assert len(seen) < 40 * 60, "no 3 flushed seconds on disk within a minute of ticks"
    finally:
        child.send_signal(signal.SIGKILL)
        rest, _ = child.communicate(timeout=30)
    out = "".join(seen) + rest
    assert child.returncode == -signal.SIGKILL
    put = [line.split() for line in out.splitlines() if line.strip()]
    last_seq = int(put[-1][0])
    last_put_t = float(put[-1][1])

    with pytest.raises(RecordingError, match="truncated: recover it with quadgcs logs recover"):
        open_recording(path)

    assert main(["logs", "recover", str(path), "-o", str(tmp_path / "fixed.mcap")]) == 0
    assert "was truncated" in capsys.readouterr().out
    fixed = open_recording(tmp_path / "fixed.mcap")
    assert not fixed.truncated
    ticks = [msg for _t, _ns, msg in fixed.messages(["/tick"])]
    seqs = [m["seq"] for m in ticks]
    assert seqs == list(range(len(seqs))), "every tick up to the last flush is there, in order"
    assert fixed.counts["/mavlink/rx"] == len(seqs)
    assert fixed.metadata["purpose"] == "crash test"
    kept_t = float(put[seqs[-1]][1])
    lost_s = last_put_t - kept_t
    assert lost_s <= 1.5, f"lost {lost_s:.2f} s ({last_seq - seqs[-1]} ticks) at SIGKILL"


def test_recover_any_truncation_point_gives_a_valid_prefix(recorded_flight, tmp_path) -> None:
    path, _counts = recorded_flight
    data = path.read_bytes()
    full = [(t, ns) for t, ns, _ in open_recording(path).raw_messages()]
    for cut in (30, len(data) // 3, len(data) // 2, len(data) - 100, len(data) - 1):
        broken = tmp_path / f"cut{cut}.mcap"
        broken.write_bytes(data[:cut])
        result = recover(broken, tmp_path / f"fixed{cut}.mcap")
        fixed = open_recording(result.output)
        got = [(t, ns) for t, ns, _ in fixed.raw_messages()]
        assert result.messages == len(got)
        if not got:
            continue
        assert not Counter(got) - Counter(full), "recovered messages all come from the file"
        newest = max(ns for _t, ns in got)
        older = Counter(m for m in full if m[1] < newest)
        assert not older - Counter(got), "nothing older than the newest kept message is lost"
    assert recover(path, tmp_path / "same.mcap").was_truncated is False


def test_recover_refuses_to_overwrite_its_input(recorded_flight) -> None:
    path, _ = recorded_flight
    with pytest.raises(RecordingError, match="must not be the input"):
        recover(path, path)
