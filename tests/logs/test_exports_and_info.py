"""CSV export, the info summary (rates, gaps, link losses) and the plot."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import pytest

from firmware_link.records import LinkEvent, LinkEventKind
from gcs.cli import main
from logs import Recorder, open_recording
from logs.csv_export import export_csv
from logs.info import summarize
from logs.plot import MATPLOTLIB_MISSING, extract_series, plot_flight


def test_csv_one_file_per_topic_with_flat_columns(recorded_flight, tmp_path) -> None:
    path, counts = recorded_flight
    files = export_csv(open_recording(path), tmp_path / "csv")
    assert set(files) == set(counts)
    with open(files["/vehicle/imu"], newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == counts["/vehicle/imu"]
    assert {"log_time_s", "rel_time_s", "acc_b.x", "acc_b.z", "gyro_b.z", "source"} <= set(rows[0])
    assert -12.0 < float(rows[-1]["acc_b.z"]) < -7.0
    with open(files["/gcs/rc_override"], newline="") as f:
        assert "throttle_us" in next(csv.reader(f))


def test_info_rates_and_largest_gap(tmp_path) -> None:
    with Recorder(tmp_path / "g.mcap", metadata={"connection": "udpin:0.0.0.0:14550"}) as rec:
        t = 0.0
        for i in range(200):
            t = 10.0 + i * 0.025 + (0.5 if i >= 100 else 0.0)  # a 0.5 s hole after 2.5 s
            rec.put("/vehicle/imu", t, {"i": i})
        rec.put("/link/events", t, LinkEvent(t, 1, LinkEventKind.LOST, "no heartbeat for 2.0 s"))
        rec.put("/link/events", t, LinkEvent(t, 1, LinkEventKind.REGAINED, "heartbeat"))
        rec.put("/gcs/events", t, {"t_s": t, "level": 4, "text": "vehicle link LOST: holding"})
        rec.event(t, "warning", "LOST link")
        rec.event(t, "info", "armed")
    summary = summarize(open_recording(rec.path))
    imu = next(s for s in summary.topics if s.topic == "/vehicle/imu")
    assert imu.count == 200
    assert imu.max_gap_s == pytest.approx(0.525, abs=1e-6)
    assert imu.max_gap_at_s == pytest.approx(99 * 0.025, abs=1e-6)
    assert imu.rate_hz == pytest.approx(199 / (199 * 0.025 + 0.5), rel=1e-6)
    assert [loss.topic for loss in summary.link_losses] == ["/link/events"]  # not repeated
    assert summary.link_losses[0].text == "no heartbeat for 2.0 s"
    assert summary.connection == "udpin:0.0.0.0:14550"


def test_info_cli_table_and_json(recorded_flight, capsys) -> None:
    path, counts = recorded_flight
    assert main(["logs", "info", str(path)]) == 0
    table = capsys.readouterr().out
    assert "/vehicle/imu" in table and "link losses: none" in table
    assert main(["logs", "info", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {t["topic"]: t["count"] for t in data["topics"]} == counts
    imu = next(t for t in data["topics"] if t["topic"] == "/vehicle/imu")
    assert imu["rate_hz"] == pytest.approx(40.0, rel=1e-6)
    assert data["duration_s"] == pytest.approx(6.0, abs=0.03)


def test_series_follow_the_flight(recorded_flight) -> None:
    path, _ = recorded_flight
    series = extract_series(open_recording(path))
    assert {"alt_setpoint_m", "alt_estimate_m", "sonar_m", "truth_alt_m", "throttle_us",
            "acc_up_est_mps2", "acc_up_imu_mps2", "mode"} <= set(series)
    truth = series["truth_alt_m"]
    assert truth.values[0] == pytest.approx(0.0, abs=1e-3)
    assert truth.values[-1] == pytest.approx(1.0, abs=0.05)  # settled on the 1 m setpoint
    assert series["throttle_us"].values.min() >= 1000


def test_plot_writes_a_png(recorded_flight, tmp_path, capsys) -> None:
    pytest.importorskip("matplotlib", reason="the [plot] extra is not installed "
                        "(pip install -e '.[plot]'; make test installs it)")
    path, _ = recorded_flight
    out = tmp_path / "flight.png"
    assert main(["logs", "plot", str(path), "-o", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.stat().st_size > 10_000


def test_plot_without_matplotlib_is_one_line_exit_1(recorded_flight, tmp_path, capsys,
                                                     monkeypatch) -> None:
    path, _ = recorded_flight
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert main(["logs", "plot", str(path), "-o", str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err.strip()
    assert err == f"quadgcs logs: {MATPLOTLIB_MISSING}"


def test_plot_of_a_flight_without_station_topics_is_refused(tmp_path) -> None:
    pytest.importorskip("matplotlib", reason="the [plot] extra is not installed "
                        "(pip install -e '.[plot]'; make test installs it)")
    with Recorder(tmp_path / "raw.mcap", metadata={}) as rec:
        rec.put_raw("rx", 1.0, b"\xfd\x00\x00\x00\x00\x01\x01\x00\x00\x00\x00\x00")
    from logs import RecordingError

    with pytest.raises(RecordingError, match="nothing to plot"):
        plot_flight(open_recording(rec.path), tmp_path / "x.png")


def test_csv_cli(recorded_flight, tmp_path, capsys) -> None:
    path, _ = recorded_flight
    out = tmp_path / "c"
    assert main(["logs", "export", str(path), "--csv", str(out), "--topic", "/gcs/estimate"]) == 0
    assert [p.name for p in Path(out).iterdir()] == ["gcs_estimate.csv"]


def test_link_losses_from_station_events_and_log_lines(tmp_path) -> None:
    with Recorder(tmp_path / "s.mcap", metadata={"url": "tcp:127.0.0.1:5760"}) as rec:
        rec.put("/gcs/events", 1.0, {"t_s": 1.0, "level": 4, "text": "vehicle link LOST: hold"})
        rec.put("/gcs/events", 2.0, {"t_s": 2.0, "level": 3, "text": "vehicle link regained"})
        rec.event(3.0, "error", "LOST: no heartbeat")
    summary = summarize(open_recording(rec.path))
    assert [(loss.topic, loss.at_s) for loss in summary.link_losses] == [("/gcs/events", 0.0)]
    assert summary.connection == "tcp:127.0.0.1:5760"
