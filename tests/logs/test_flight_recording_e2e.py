"""A real flight: `quadgcs fly` on the bundled SITL, recorded, read, exported, replayed."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from gcs.cli import main
from logs import open_recording
from logs.tlog import read_tlog

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def sitl_flight(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("fly") / "flight.mcap"
    proc = subprocess.run(
        [sys.executable, "-m", "gcs", "fly", "--hold", "2", "--speedup", "2", "--seed", "11",
         "-o", str(out)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return out


def test_the_flight_recording_holds_what_a_rerun_needs(sitl_flight) -> None:
    rec = open_recording(sitl_flight)
    counts = rec.counts
    for topic in ("/vehicle/imu", "/vehicle/rangefinder", "/vehicle/attitude", "/gcs/estimate",
                  "/gcs/alt_controller", "/gcs/rc_override", "/mavlink/rx", "/mavlink/tx"):
        assert counts.get(topic, 0) > 0, topic
    assert counts["/mavlink/rx"] > counts["/vehicle/imu"]
    assert rec.duration_s > 5.0
    imu = next(m for _t, _ns, m in rec.messages(["/vehicle/imu"]))
    assert {"t_s", "acc_b", "gyro_b"} <= set(imu)  # receive time and the sensor values
    assert rec.metadata["software_version"]


def test_real_frames_export_to_a_tlog_pymavlink_reads(sitl_flight, tmp_path) -> None:
    tlog = tmp_path / "flight.tlog"
    assert main(["logs", "export", str(sitl_flight), "--tlog", str(tlog)]) == 0
    rec = open_recording(sitl_flight)
    frames = list(read_tlog(tlog))
    assert len(frames) == rec.counts["/mavlink/rx"] + rec.counts["/mavlink/tx"]
    proc = subprocess.run(
        [sys.executable, "-m", "tests.logs.pymavlink_dump", str(tlog)],
        cwd=REPO, capture_output=True, text=True, timeout=120, check=True,
    )
    digest = json.loads(proc.stdout)
    assert digest["count"] == len(frames)  # every frame decodes: real CRCs, nothing torn
    assert {"HEARTBEAT", "RC_CHANNELS_OVERRIDE"} <= set(digest["types"])


def test_info_replay_and_plot_on_the_flight(sitl_flight, tmp_path, capsys) -> None:
    assert main(["logs", "info", str(sitl_flight), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    rec = open_recording(sitl_flight)
    events = rec.messages(["/link/events"]) if "/link/events" in rec.counts else []
    lost = [m for _t, _ns, m in events if m["kind"] == "lost"]
    assert len(info["link_losses"]) == len(lost)  # none on a calm machine; under load, as logged
    assert {t["topic"] for t in info["topics"]} == set(rec.topics)
    assert main(["replay", str(sitl_flight), "--max"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert any("mode ALT_HOLD" in line or "mode STABILIZE" in line for line in lines)
    assert lines[-1].startswith("replayed ")
    pytest.importorskip("matplotlib", reason="the [plot] extra is not installed "
                        "(pip install -e '.[plot]'; make test installs it)")
    assert main(["logs", "plot", str(sitl_flight), "-o", str(tmp_path / "f.png")]) == 0


def test_every_schema_of_the_real_flight_is_foxglove_readable(sitl_flight) -> None:
    from mcap.reader import make_reader

    from tests.logs.foxglove_schema_check import foxglove_schema_problems

    with open(sitl_flight, "rb") as f:
        summary = make_reader(f).get_summary()
    for schema in summary.schemas.values():
        assert schema.encoding == "jsonschema"
        assert foxglove_schema_problems(json.loads(schema.data)) == [], schema.name
