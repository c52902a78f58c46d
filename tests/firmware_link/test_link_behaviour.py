"""Link behaviour against the scripted vehicle over real TCP sockets and pseudo-terminals:
any-frame watchdog, GCS heartbeat control, sends under backpressure, arming refusals as each
firmware words them, firmware identification and loud parameters."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator

import pytest

from firmware_link import LinkError, LinkUsageError, ParamError, VehicleLink
from firmware_link.connection import parse_connection_string
from firmware_link.frames import FrameEndpoint
from firmware_link.protocol import WireVersion
from firmware_link.records import Attitude, Dialect, FlightMode, LinkEventKind, RcCommand
from tests.firmware_link.peer import FakeVehicle, wait_until
from tests.firmware_link.test_link_peer import events, poll_until
from worldfile import key_from_passphrase


@pytest.fixture
def apm25() -> Iterator[FakeVehicle]:
    v = FakeVehicle("apm25").start()
    yield v
    v.stop()


def test_telemetry_without_heartbeats_keeps_the_link_alive() -> None:
    v = FakeVehicle("copter4", companion=False).start()
    try:
        with VehicleLink.open(v.url) as link:
            v.state.rates_hz["ATTITUDE"] = 20.0
            poll_until(link, lambda rs: any(isinstance(r, Attitude) for r in rs))
            v.state.heartbeats = False  # heartbeat frames lost, telemetry flowing
            records = poll_until(
                link, lambda rs: time.monotonic() - link.last_heartbeat_s > 3.0, timeout_s=6.0)
            assert not link.lost and not events(records, LinkEventKind.LOST)
            assert link.last_rx_s > link.last_heartbeat_s + 2.5
            v.paused.set()  # now nothing at all comes
            records = poll_until(link, lambda rs: events(rs, LinkEventKind.LOST), timeout_s=4.0)
            lost = events(records, LinkEventKind.LOST)[0]
            assert 1.5 <= lost.t_s - link.last_rx_s <= 2.0
            assert link.lost
            v.paused.clear()
            poll_until(link, lambda rs: events(rs, LinkEventKind.REGAINED), timeout_s=3.0)
    finally:
        v.stop()


def test_before_any_frame_times_are_minus_infinity() -> None:
    spec = parse_connection_string("tcp:127.0.0.1:5760")
    endpoint = FrameEndpoint(None, source_system=255, source_component=190, clock=time.monotonic)
    link = VehicleLink(spec, endpoint, clock=time.monotonic, wall_clock=time.time,
                       signing_key=None)
    assert link.last_rx_s == link.last_heartbeat_s == -math.inf
    assert link.dialect is Dialect.UNKNOWN and link.pending_override is None
    assert not link.rc_override(RcCommand())  # no transport: dropped and counted
    assert link.stats.tx_dropped == 1


def test_gcs_heartbeat_can_be_switched_off_and_on(apm25: FakeVehicle) -> None:
    with VehicleLink.open(apm25.url) as link:
        assert link.gcs_heartbeat
        link.set_gcs_heartbeat(False)
        link.set_mode(FlightMode.STABILIZE)  # acknowledged: everything sent before has arrived
        heard = apm25.state.gcs_heartbeats
        quiet_until = time.monotonic() + 2.5 * link.heartbeat_period_s
        poll_until(link, lambda rs: time.monotonic() > quiet_until, timeout_s=4.0)
        assert apm25.state.gcs_heartbeats == heard  # silent: the vehicle's GCS failsafe runs
        link.set_gcs_heartbeat(True)
        link.poll()  # the next poll greets at once
        assert wait_until(lambda: apm25.state.gcs_heartbeats == heard + 1, 2.0)


@pytest.mark.parametrize(("profile", "serial"), [("copter4", False), ("apm25", True)],
                         ids=["copter4-tcp", "apm25-pty"])
def test_a_stalled_reader_never_blocks_an_override(profile: str, serial: bool) -> None:
    v = FakeVehicle(profile, serial=serial, companion=False, rcvbuf=4096).start()
    try:
        with VehicleLink.open(v.url) as link:
            link.poll()
            v.stall_rx.set()
            sent = 0
            while link.stats.tx_backpressure == 0:  # fill the kernel's buffers
                assert link.rc_override(RcCommand(throttle_us=1000 + sent % 1000))
                sent += 1
                assert sent < 200_000, "the transport never pushed back"
            for k in range(50):  # each returns at once and replaces the one waiting
                last = RcCommand(throttle_us=1100 + k)
                assert link.rc_override(last)
                sent += 1
            assert link.pending_override == (1500, 1500, 1149, 1500, 65535, 65535, 65535, 65535)
            stats = link.stats
            assert stats.tx_dropped_overrides >= 49
            assert stats.tx_queued_bytes > 0 and stats.tx_backpressure >= 1
            assert link.flush() == link.stats.tx_queued_bytes > 0  # still stalled: bytes wait
            queued = 0
            while link.send_set_mode(FlightMode.STABILIZE):  # commands queue, bounded
                queued += 1
                assert queued < 10_000
            assert link.stats.tx_queue_overflows == 1 and link.stats.tx_dropped >= 1
            records = link.poll()  # a full buffer is not a lost port
            assert not events(records, LinkEventKind.RECONNECTING)
            assert link.stats.reconnects == 0

            v.stall_rx.clear()
            poll_until(link, lambda rs: link.stats.tx_queued_bytes == 0
                       and link.pending_override is None, timeout_s=10.0)
            dropped = link.stats.tx_dropped_overrides
            assert wait_until(lambda: len(v.state.overrides) == sent - dropped, 5.0)
            assert v.state.overrides[-1][2][2] == 1149  # the newest went out, once
            assert wait_until(lambda: v.state.rx_types.count("SET_MODE") == queued, 5.0)
    finally:
        v.stop()


def test_apm25_unsupported_refusal_is_retried_and_named(apm25: FakeVehicle) -> None:
    apm25.state.arm_refusal = "PreArm: INS not calibrated"
    with VehicleLink.open(apm25.url) as link:
        with pytest.raises(LinkError) as info:
            link.arm(timeout_s=3.0)
        assert "refused to arm (unsupported): PreArm: INS not calibrated" in str(info.value)
        with pytest.raises(LinkError) as info:
            link.arm(timeout_s=2.5, retry=True)
        text = str(info.value)
        assert "\n" not in text and "PreArm: INS not calibrated" in text
        assert "kept refusing for 2.5 s" in text
        apm25.state.arm_refusals_left = 2
        link.arm(timeout_s=10.0, retry=True)
        assert link.armed and apm25.state.arm_refusals_left == 0


def test_apm25_silent_refusal_says_what_3_2_1_refuses_silently(apm25: FakeVehicle) -> None:
    apm25.state.arm_refusal_silent = True
    with VehicleLink.open(apm25.url) as link, pytest.raises(LinkError, match="throttle"):
        link.arm(timeout_s=2.0)


@pytest.mark.parametrize("serial", [False, True], ids=["tcp", "pty"])
def test_identifies_3_2_1_by_parameters_and_banner(serial: bool) -> None:
    v = FakeVehicle("apm25", serial=serial).start()
    try:
        with VehicleLink.open(v.url) as link:
            fw = link.firmware
            assert fw.dialect is Dialect.APM25 and link.dialect is Dialect.APM25
            assert fw.version == "" and fw.name == "ArduCopter 3.x"
            assert fw.gcs_sysid_param == "SYSID_MYGCS" and fw.wire is WireVersion.V1
            joined = " | ".join(fw.evidence)
            assert "AUTOPILOT_VERSION not answered" in joined and "THR_MID exists" in joined
            (event,) = events(link.poll(), LinkEventKind.DIALECT)
            assert event.detail.startswith("ArduCopter 3.x (no version given): dialect APM25")
            # 3.2.1 sends nothing else while its parameter list runs: not asked at connect
            assert "PARAM_REQUEST_LIST" not in v.state.rx_types
            link.arm()
            assert link.identify(ask_banner=True).version == ""  # never while armed
            assert "PARAM_REQUEST_LIST" not in v.state.rx_types
            link.disarm()
            fw = link.identify(ask_banner=True)
            assert fw.version == "ArduCopter V3.2.1" and fw.version_number == (3, 2, 1)
            assert any("banner 'ArduCopter V3.2.1'" in e for e in fw.evidence)
    finally:
        v.stop()


def test_a_parameter_download_brings_the_banner_for_the_next_identify(apm25: FakeVehicle) -> None:
    with VehicleLink.open(apm25.url) as link:
        assert link.firmware.version == ""
        link.fetch_params()
        assert link.identify().version == "ArduCopter V3.2.1"


def test_identifies_4_7_by_autopilot_version() -> None:
    v = FakeVehicle("copter4").start()
    try:
        with VehicleLink.open(v.url) as link:
            fw = link.firmware
            assert (fw.dialect, fw.version, fw.gcs_sysid_param, fw.wire) == (
                Dialect.COPTER4, "ArduCopter V4.7.0-dev", "MAV_GCS_SYSID", WireVersion.V2)
            assert any("AUTOPILOT_VERSION" in e and "d2e4299f" in e for e in fw.evidence)
            assert "PARAM_REQUEST_LIST" not in v.state.rx_types  # no banner needed
    finally:
        v.stop()


@pytest.mark.parametrize("answers_version", [True, False], ids=["version", "params-only"])
def test_a_4x_on_a_mavlink1_port_is_flown_as_4x(answers_version: bool) -> None:
    v = FakeVehicle("copter4", wire_v1=True, companion=False)
    v.state.answers_version = answers_version
    v.state.sends_banner = False
    v.start()
    try:
        with VehicleLink.open(v.url) as link:
            fw = link.firmware
            assert fw.dialect is Dialect.COPTER4 and fw.wire is WireVersion.V1
            assert fw.version == ("ArduCopter V4.7.0-dev" if answers_version else "")
            assert any("not an APM 2.5" in e for e in fw.evidence)
            link.arm(force=True)  # 4.x force-arm: not refused as on an APM 2.5
            assert link.armed
            link.rc_override(RcCommand(throttle_us=1200))
            assert wait_until(lambda: bool(v.state.overrides))
            assert v.state.overrides[-1][1] == 18  # MAVLink 1 form, as the port speaks
        with pytest.raises(LinkUsageError, match="cannot sign"):
            VehicleLink.open(v.url, signing_key=key_from_passphrase("k"))
    finally:
        v.stop()


def test_with_no_evidence_the_wire_is_only_a_hint() -> None:
    v = FakeVehicle("apm25")
    v.state.params.clear()
    v.state.sends_banner = False
    v.start()
    try:
        with VehicleLink.open(v.url) as link:
            assert link.dialect is Dialect.APM25
            assert any("only the wire version" in e for e in link.firmware.evidence)
            assert link.firmware.version == ""
    finally:
        v.stop()


def test_read_params_names_every_missing_one(apm25: FakeVehicle) -> None:
    with VehicleLink.open(apm25.url) as link:
        assert link.read_params(["THR_MID", "THR_MIN"]) == {"THR_MID": 500.0, "THR_MIN": 130.0}
        with pytest.raises(ParamError) as info:
            link.read_params(["THR_MID", "NOPE_A", "NOPE_B"], timeout_s=0.5)
        assert info.value.names == ("NOPE_A", "NOPE_B")
        assert "no value for parameters NOPE_A, NOPE_B within 0.5 s" in str(info.value)
        assert isinstance(info.value, LinkError) and info.value.exit_code == 1


def test_set_param_confirms_or_says_what_the_vehicle_stored(apm25: FakeVehicle) -> None:
    apm25.state.limits["THR_MID"] = (300.0, 700.0)
    with VehicleLink.open(apm25.url) as link:
        assert link.set_param("THR_MID", 650) == 650.0
        with pytest.raises(ParamError, match="stored THR_MID = 700, not 800") as info:
            link.set_param("THR_MID", 800)
        assert info.value.names == ("THR_MID",)
        with pytest.raises(LinkUsageError, match="not a whole number"):
            link.set_param("THR_MID", 450.5)
        with pytest.raises(LinkUsageError, match="outside its range"):
            link.set_param("THR_MID", 40000)
        with pytest.raises(ParamError, match="no value for parameter NOPE"):
            link.set_param("NOPE", 1.0, timeout_s=0.5)
        assert link.get_param("THR_MID") == 700.0


def test_a_rangefinder_record_carries_the_frames_lost_before_it(apm25: FakeVehicle) -> None:
    """The estimator tells a sonar's silence from the radio's by whether the stream between
    two readings arrived whole: each reading carries the link's lost-frame count."""
    from pymavlink.dialects.v10 import ardupilotmega as mav1

    from firmware_link.records import Rangefinder

    enc = mav1.MAVLink(None, srcSystem=1, srcComponent=50)  # a sender of its own sequence
    with VehicleLink.open(apm25.url) as link:
        poll_until(link, lambda rs: link.stats.rx_messages > 0)

        def reading(seq: int, cm: int) -> Rangefinder:
            enc.seq = seq
            apm25.inject(mav1.MAVLink_rangefinder_message(cm / 100.0, 0.0)
                         .pack(enc, force_mavlink1=True))

            def mine(rs: list) -> list[Rangefinder]:  # the vehicle's own stream reads 0.75 m
                return [r for r in rs if isinstance(r, Rangefinder)
                        and round(r.distance_m * 100) == cm]
            return mine(poll_until(link, lambda rs: bool(mine(rs))))[0]

        first = reading(10, 95)
        assert reading(11, 96).link_lost == first.link_lost  # nothing lost between
        after_gap = reading(15, 97)  # three frames of that sender lost
        assert after_gap.link_lost == first.link_lost + 3
        assert after_gap.link_lost <= link.stats.lost_messages
