"""Recording round trip: what is put is what is read back, on the right timeline."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from firmware_link.records import Imu, LinkEvent, LinkEventKind
from logs import Recorder, RecordingError, open_recording
from logs.encoding import vector
from tests.logs.conftest import ANCHOR_NS
from tests.logs.flightgen import record, synthetic_flight


def test_counts_per_topic_match_what_was_put(recorded_flight) -> None:
    path, counts = recorded_flight
    rec = open_recording(path)
    assert rec.counts == dict(sorted(counts.items()))
    assert not rec.truncated
    read_back: dict[str, int] = {}
    last_ns = 0
    for topic, log_ns, _msg in rec.messages():
        read_back[topic] = read_back.get(topic, 0) + 1
        assert log_ns >= last_ns, "messages must come in log-time order"
        last_ns = log_ns
    assert read_back == counts


def test_log_time_is_anchor_plus_monotonic_seconds(tmp_path: Path) -> None:
    imu = Imu(123.456, 1, (0.1, -0.2, -9.81), (0.0, 0.01, 0.0), "RAW_IMU", 42)
    with Recorder(tmp_path / "a.mcap", metadata={}, anchor_ns=ANCHOR_NS) as rec:
        rec.put("/vehicle/imu", imu.t_s, imu)
    (_topic, log_ns, msg), = list(open_recording(rec.path).messages(["/vehicle/imu"]))
    assert log_ns == ANCHOR_NS + 123_456_000_000
    assert msg["t_s"] == pytest.approx(123.456)
    assert vector(msg["acc_b"]) == pytest.approx(imu.acc_b)
    assert msg["acc_b"]["z"] == pytest.approx(-9.81)  # flat x/y/z objects plot by path
    assert msg["time_usec"] == 42


def test_schemas_are_json_schema_from_field_types(recorded_flight) -> None:
    path, _ = recorded_flight
    rec = open_recording(path)
    info = rec.topic_info
    assert info["/vehicle/imu"].schema_name == "firmware_link.records.Imu"
    assert info["/vehicle/imu"].message_encoding == "json"
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    by_name = {s.name: s for s in summary.schemas.values()}
    imu = json.loads(by_name["firmware_link.records.Imu"].data)
    assert by_name["firmware_link.records.Imu"].encoding == "jsonschema"
    assert imu["properties"]["sysid"] == {"type": "integer"}
    assert set(imu["properties"]["acc_b"]["properties"]) == {"x", "y", "z"}
    heartbeat = json.loads(by_name["firmware_link.records.Heartbeat"].data)
    assert heartbeat["properties"]["system_status"]["type"] == "integer"  # enums as integers
    assert heartbeat["properties"]["armed"] == {"type": "boolean"}
    raw = json.loads(by_name["quadgcs.MavlinkFrame"].data)
    assert raw["properties"]["data"]["contentEncoding"] == "base64"


def test_metadata_round_trips_with_types(recorded_flight) -> None:
    path, _ = recorded_flight
    meta = open_recording(path).metadata
    assert meta["vehicle"] == "vehicle1"
    assert meta["connection"] == "tcp:127.0.0.1:5760"
    assert meta["params"] == {"MOT_THST_HOVER": 0.39}
    assert meta["software_version"]
    assert int(meta["anchor_ns"]) == ANCHOR_NS


def test_raw_frames_are_base64_with_length(tmp_path: Path) -> None:
    frame = bytes(range(40))
    with Recorder(tmp_path / "r.mcap", metadata={}, anchor_ns=0) as rec:
        rec.put_raw("tx", 1.0, frame)
        rec.put_raw("rx", 2.0, frame[::-1])
    msgs = list(open_recording(rec.path).messages(["/mavlink/rx", "/mavlink/tx"]))
    assert [m[0] for m in msgs] == ["/mavlink/tx", "/mavlink/rx"]
    import base64

    assert base64.b64decode(msgs[0][2]["data"]) == frame
    assert msgs[0][2]["len"] == 40


def test_bad_direction_and_level_are_refused(tmp_path: Path) -> None:
    with Recorder(tmp_path / "r.mcap", metadata={}) as rec:
        with pytest.raises(RecordingError, match="direction"):
            rec.put_raw("sideways", 1.0, b"\xfd")
        with pytest.raises(RecordingError, match="log level"):
            rec.event(1.0, "loud", "x")


def test_events_are_foxglove_logs(tmp_path: Path) -> None:
    with Recorder(tmp_path / "r.mcap", metadata={}, anchor_ns=ANCHOR_NS) as rec:
        rec.event(5.5, "warning", "LOST link: no heartbeat for 2 s")
    (_t, log_ns, msg), = open_recording(rec.path).messages(["/log"])
    assert open_recording(rec.path).topic_info["/log"].schema_name == "foxglove.Log"
    assert msg["level"] == 3
    assert msg["timestamp"]["sec"] * 10**9 + msg["timestamp"]["nsec"] == log_ns
    assert msg["message"].startswith("LOST")


def test_directory_gets_utc_and_vehicle_named_files(tmp_path: Path) -> None:
    a = Recorder(tmp_path / "flights", metadata={}, vehicle="quad 2")
    b = Recorder(tmp_path / "flights", metadata={}, vehicle="quad 2")
    a.close()
    b.close()
    assert a.path.parent == tmp_path / "flights"
    assert a.path.name.endswith("Z_quad_2.mcap")
    assert a.path != b.path
    assert a.path.name[:4].isdigit() and a.path.name[10] == "T"


def test_nan_becomes_null_and_bad_payloads_are_counted_not_fatal(tmp_path: Path) -> None:
    with Recorder(tmp_path / "r.mcap", metadata={}) as rec:
        rec.put("/x", 1.0, {"alt_m": math.nan, "ok": 1.0})
        rec.put("/x", 1.1, 12345)  # neither dataclass nor dict
        rec.put("/x", math.inf, {"alt_m": 1.0})  # no place on the timeline
        rec.put("/x", 1.2, {"obj": object()})  # no JSON form: written as its text
    stats = rec.stats
    assert stats.written["/x"] == 2
    assert stats.rejected["/x"] == 2
    first, second = (m for _t, _ns, m in open_recording(rec.path).messages(["/x"]))
    assert first == {"alt_m": None, "ok": 1.0}
    assert second["obj"].startswith("<object object")


def test_dict_payload_is_copied_at_put(tmp_path: Path) -> None:
    payload = {"alt_m": 1.0}
    with Recorder(tmp_path / "r.mcap", metadata={}) as rec:
        rec.put("/x", 1.0, payload)
        payload["alt_m"] = 2.0  # the station reuses its dict on the next tick
    (_t, _ns, msg), = open_recording(rec.path).messages(["/x"])
    assert msg["alt_m"] == 1.0


def test_full_queue_drops_and_counts(tmp_path: Path) -> None:
    n = 100_000
    rec = Recorder(tmp_path / "r.mcap", metadata={}, max_queue=50)
    for i in range(n):
        rec.put("/burst", i * 1e-4, {"i": i})
    rec.close()
    stats = rec.stats
    assert stats.written.get("/burst", 0) + stats.dropped.get("/burst", 0) == n
    assert stats.dropped["/burst"] > 0
    recording = open_recording(rec.path)
    assert recording.counts["/burst"] == stats.written["/burst"]
    warnings = [m["message"] for _t, _ns, m in recording.messages(["/log"])]
    assert warnings and all("recorder queue full" in w for w in warnings)
    assert warnings[-1].endswith(f"({stats.dropped['/burst']} in all)")  # the hole is in the file


def test_a_simulated_time_producer_waits_for_the_writer_and_loses_nothing(
        tmp_path: Path) -> None:
    # the same burst into the same small queue, from a lockstep flight: it waits instead
    n = 20_000
    rec = Recorder(tmp_path / "r.mcap", metadata={}, max_queue=50, block_when_full=True)
    for i in range(n):
        rec.put("/burst", i * 1e-4, {"i": i})
    rec.close()
    assert rec.stats.dropped == {} and rec.stats.written["/burst"] == n
    recording = open_recording(rec.path)
    assert [m["i"] for _t, _ns, m in recording.messages(["/burst"])] == list(range(n))


def test_put_after_close_is_counted_as_dropped(tmp_path: Path) -> None:
    rec = Recorder(tmp_path / "r.mcap", metadata={})
    rec.close()
    rec.put("/late", 1.0, {"a": 1})
    rec.close()  # idempotent
    assert rec.stats.dropped == {"/late": 1}


def test_unwritable_location_is_one_clear_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(RecordingError, match="cannot"):
        Recorder(blocker / "sub" / "f.mcap", metadata={})


def test_link_event_enum_value_recorded(tmp_path: Path) -> None:
    with Recorder(tmp_path / "r.mcap", metadata={}) as rec:
        rec.put("/gcs/events", 1.0, LinkEvent(1.0, 1, LinkEventKind.LOST, "no heartbeat"))
    (_t, _ns, msg), = open_recording(rec.path).messages(["/gcs/events"])
    assert msg["kind"] == "lost"


def test_recording_survives_many_flushes(tmp_path: Path) -> None:
    """A flush interval far below the feed time makes many chunks; all are indexed."""
    rng = np.random.default_rng(3)
    with Recorder(tmp_path / "r.mcap", metadata={}, flush_interval_s=0.001) as rec:
        counts = record(rec, synthetic_flight(2.0, rng))
    got = open_recording(rec.path).counts
    for topic, n in counts.items():
        assert got[topic] == n


def test_records_and_config_rebuild_for_a_rerun(tmp_path: Path) -> None:
    """What a rerun needs: sensor records with receive times back as records, config as data."""
    from dataclasses import dataclass

    from firmware_link.records import Heartbeat, Rangefinder, SystemStatus
    from logs.encoding import from_jsonable

    @dataclass(frozen=True)
    class EstimatorConfig:
        complementary_tc_s: float = 1.0
        gate_m: float = 0.3

    imu = Imu(12.5, 1, (0.1, -0.2, -9.81), (0.0, 0.01, 0.0), "RAW_IMU", 7)
    sonar = Rangefinder(12.51, 1, math.nan, False, "RANGEFINDER")
    beat = Heartbeat(12.6, 1, 1, 2, True, SystemStatus.ACTIVE, 209)
    with Recorder(
        tmp_path / "r.mcap", metadata={"estimator": EstimatorConfig()}, anchor_ns=0
    ) as rec:
        for topic, record in (("/vehicle/imu", imu), ("/vehicle/rangefinder", sonar),
                              ("/vehicle/heartbeat", beat)):
            rec.put(topic, record.t_s, record)
    recording = open_recording(rec.path)
    back = {t: m for t, _ns, m in recording.messages()}
    assert from_jsonable(Imu, back["/vehicle/imu"]) == imu
    got_sonar = from_jsonable(Rangefinder, back["/vehicle/rangefinder"])
    assert math.isnan(got_sonar.distance_m) and got_sonar.valid is False
    assert from_jsonable(Heartbeat, back["/vehicle/heartbeat"]) == beat
    assert from_jsonable(Heartbeat, back["/vehicle/heartbeat"]).system_status is SystemStatus.ACTIVE
    assert recording.metadata["estimator"] == {"complementary_tc_s": 1.0, "gate_m": 0.3}


def test_world_and_mission_files_go_into_the_metadata_as_text(tmp_path: Path) -> None:
    from logs import files_metadata

    world = tmp_path / "room.toml"
    world.write_text('[room]\nsize_m = [6.0, 4.0, 3.0]\n')
    meta = files_metadata(world=world, mission=tmp_path / "gone.toml", config=None)
    with Recorder(tmp_path / "r.mcap", metadata=meta) as rec:
        rec.put("/x", 1.0, {"a": 1})
    got = open_recording(rec.path).metadata
    assert got["world"] == world.read_text()
    assert got["world_path"] == str(world)
    assert got["mission"].startswith("<unreadable")
    assert "config" not in got
