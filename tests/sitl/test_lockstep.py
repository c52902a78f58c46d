"""The SITL in lockstep: time passes only when its caller says, and what crosses a port is the
MAVLink the TCP endpoints send."""

from __future__ import annotations

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.lockstep import PORT_BACKLOG_BYTES, LinkFaults, MemoryPort, PortClosed, Stall, start


def _open(port: MemoryPort) -> MemoryPort:
    """The port with a client on it, as the station's link opening it does."""
    port.connect()
    return port


def _decode(data: bytes) -> list[mavlink.MAVLink_message]:
    parser = mavlink.MAVLink(None)
    return [m for m in parser.parse_buffer(data) or [] if m.get_type() != "BAD_DATA"]


def test_time_moves_only_when_asked_and_never_back() -> None:
    sitl = start(seed=1)
    assert sitl.t_s == 0.0 and sitl.ticks == 0
    sitl.advance_to(0.025)
    # the 100 Hz ticks due by 25 ms ran; the clock reads the time asked, between ticks
    assert sitl.ticks == 2 and sitl.t_s == pytest.approx(0.025)
    sitl.advance_to(0.01)
    assert sitl.t_s == pytest.approx(0.025) and sitl.ticks == 2


def test_waiting_for_bytes_stops_at_the_tick_that_sent_them() -> None:
    sitl = start(seed=1)
    port = _open(sitl.vehicle_port(1))
    port.wait_readable(5.0)
    # the autopilot's first heartbeat goes out on its first tick: not five seconds later
    assert port.readable and sitl.t_s == pytest.approx(0.01)
    kinds = {m.get_type() for m in _decode(port.read(PORT_BACKLOG_BYTES))}
    assert "HEARTBEAT" in kinds
    # nothing more until time passes; a wait with nothing to come runs out its time
    assert not port.readable


def test_a_request_written_is_answered_on_the_same_port() -> None:
    sitl = start(seed=1)
    port = _open(sitl.vehicle_port(1))
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    req = mavlink.MAVLink_param_request_read_message(1, 1, b"SYSID_THISMAV", -1)
    port.write(req.pack(gcs, force_mavlink1=True))
    sitl.advance_to(0.05)
    values = [m for m in _decode(port.read(PORT_BACKLOG_BYTES))
              if m.get_type() == "PARAM_VALUE"]
    assert [v.param_id for v in values] == ["SYSID_THISMAV"]
    assert values[0].param_value == 1.0


def test_truth_and_mocap_ports_stream_at_their_rates() -> None:
    sitl = start(seed=1)
    truth, mocap = _open(sitl.truth_port()), _open(sitl.mocap_port())
    sitl.advance_to(1.0)
    reports = [m for m in _decode(truth.read(PORT_BACKLOG_BYTES))
               if m.get_type() == "LOCAL_POSITION_NED"]
    poses = [m for m in _decode(mocap.read(PORT_BACKLOG_BYTES))
             if m.get_type() == "ATT_POS_MOCAP"]
    assert 49 <= len(reports) <= 51  # 50 Hz
    assert 85 <= len(poses) <= 100  # 100 Hz, after the mocap system's latency
    # standing on the floor: the centre of gravity a few cm up (NED: z negative)
    assert -0.2 < reports[-1].z < 0.0


def test_same_seed_same_bytes_other_seed_other_bytes() -> None:
    def run(seed: int) -> bytes:
        sitl = start(seed=seed)
        port = _open(sitl.vehicle_port(1))
        gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
        port.write(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 40, 1)
                   .pack(gcs, force_mavlink1=True))
        out = bytearray()
        for k in range(1, 101):
            sitl.advance_to(k * 0.01)
            out += port.read(PORT_BACKLOG_BYTES)
        return bytes(out)

    first = run(7)
    assert len(first) > 10_000
    assert run(7) == first
    assert run(8) != first


def test_a_closed_port_refuses_and_is_no_longer_fed() -> None:
    sitl = start(seed=1)
    port = _open(sitl.vehicle_port(1))
    port.close()
    sitl.advance_to(0.5)
    with pytest.raises(PortClosed):
        port.read(10)
    with pytest.raises(PortClosed):
        port.write(b"x")


def test_bad_profile_is_one_line() -> None:
    with pytest.raises(ValueError, match="profile 'apm26': expected one of apm25, copter4"):
        start("apm26")


def _heartbeats(port: MemoryPort) -> list[float]:
    return [m.get_type() for m in _decode(port.read(PORT_BACKLOG_BYTES))].count("HEARTBEAT")


def test_a_fade_loses_one_way_for_its_window_only() -> None:
    sitl = start(seed=1)
    port = _open(sitl.vehicle_port(1, LinkFaults(fade="down", fade_start_s=1.0, fade_s=2.0)))
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    seen = []
    for second in range(4):
        sitl.advance_to(second + 0.995)
        seen.append(_heartbeats(port))
    # 1 Hz heartbeats: one in each second but the two faded ones
    assert seen == [1, 0, 0, 1] and port.lost_frames[0] > 2 and port.lost_frames[1] == 0
    # the uplink is untouched by a downlink fade: a request in the fade is answered after it
    sitl2 = start(seed=1)
    port2 = _open(sitl2.vehicle_port(1, LinkFaults(fade="up", fade_start_s=0.0, fade_s=1.0)))
    req = mavlink.MAVLink_param_request_read_message(1, 1, b"SYSID_THISMAV", -1)
    port2.write(req.pack(gcs, force_mavlink1=True))
    sitl2.advance_to(1.5)
    assert "PARAM_VALUE" not in {m.get_type() for m in _decode(port2.read(PORT_BACKLOG_BYTES))}
    port2.write(req.pack(gcs, force_mavlink1=True))
    sitl2.advance_to(1.6)
    assert "PARAM_VALUE" in {m.get_type() for m in _decode(port2.read(PORT_BACKLOG_BYTES))}
    assert port2.lost_frames == (0, 1)


def test_frame_loss_is_whole_frames_at_its_rate_from_its_seed() -> None:
    def run(seed: int) -> tuple[int, int, bytes]:
        sitl = start(seed=1)
        port = _open(sitl.vehicle_port(1, LinkFaults(loss=0.2, seed=seed)))
        clean = _open(sitl.vehicle_port(1))
        gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
        for p in (port, clean):
            p.write(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 40, 1)
                    .pack(gcs, force_mavlink1=True))
        sitl.advance_to(3.0)
        got = port.read(PORT_BACKLOG_BYTES)
        return len(_decode(got)), len(_decode(clean.read(PORT_BACKLOG_BYTES))), got

    kept, total, data = run(3)
    # every byte that arrives is part of a whole, good frame
    assert sum(len(m.get_msgbuf()) for m in _decode(data)) == len(data)
    assert 0.7 * total < kept < 0.9 * total
    assert run(3)[2] == data and run(4)[2] != data


def test_frame_loss_keeps_to_its_window() -> None:
    sitl = start(seed=1)
    port = _open(sitl.vehicle_port(1, LinkFaults(loss=0.5, loss_start_s=1.0, loss_s=1.0)))
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    port.write(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 40, 1)
               .pack(gcs, force_mavlink1=True))
    got, lost = [], []
    for second in range(3):
        sitl.advance_to(second + 0.995)
        got.append(len(_decode(port.read(PORT_BACKLOG_BYTES))))
        lost.append(port.lost_frames[0])
    # before the window nothing is lost; in it about half; after it nothing more
    assert lost[0] == 0 and lost[2] == lost[1] and 0.3 * got[2] < lost[1] < 0.7 * got[2]
    assert 0.3 * got[2] < got[1] < 0.7 * got[2]


def test_bad_faults_are_one_line() -> None:
    with pytest.raises(ValueError, match="fade 'sideways': expected one of none, down, up"):
        LinkFaults(fade="sideways")
    with pytest.raises(ValueError, match=r"loss 1.5: expected a probability in \[0, 1\)"):
        LinkFaults(loss=1.5)
    with pytest.raises(ValueError, match="expected seconds >= 0"):
        LinkFaults(loss=0.3, loss_s=-1.0)


def test_a_port_nobody_opened_gets_nothing_as_a_tcp_endpoint_without_a_client() -> None:
    sitl = start(seed=1)
    early, late = sitl.mocap_port(), sitl.mocap_port()
    early.connect()
    sitl.advance_to(2.0)
    late.connect()
    sitl.advance_to(2.5)
    n_early = len(_decode(early.read(PORT_BACKLOG_BYTES)))
    n_late = len(_decode(late.read(PORT_BACKLOG_BYTES)))
    # 100 Hz poses: the late client has only the half second since it came
    assert n_early > 190 and 45 <= n_late <= 51


def test_a_stalled_sitl_sends_nothing_then_what_it_missed_at_once() -> None:
    sitl = start(seed=1)
    sitl.stall = Stall(stop_s=0.3, every_s=0.6, start_s=1.0)  # stopped over [1.3, 1.6) and on
    port, truth = _open(sitl.vehicle_port(1)), _open(sitl.truth_port())
    sitl.advance_to(1.3)
    port.read(PORT_BACKLOG_BYTES), truth.read(PORT_BACKLOG_BYTES)
    ticks = sitl.ticks
    sitl.advance_to(1.55)
    # the clock runs on; the SITL neither flies nor sends
    assert sitl.t_s == pytest.approx(1.55) and sitl.ticks == ticks
    assert not port.readable and not truth.readable
    # a wait in the stall ends when the SITL wakes, with the 30 ticks it missed run at once
    truth.wait_readable(1.0)
    assert sitl.t_s == pytest.approx(1.6) and sitl.ticks == ticks + 30
    # the truth reports (50 Hz) of the whole stall, stamped with their own times
    reports = [m for m in _decode(truth.read(PORT_BACKLOG_BYTES))
               if m.get_type() == "LOCAL_POSITION_NED"]
    assert len(reports) == 15
    assert reports[-1].time_boot_ms - reports[0].time_boot_ms == pytest.approx(280, abs=10)
    # the next heartbeat (1 Hz, due at 2.0 s) falls in the next stall and comes when it ends
    port.wait_readable(1.0)
    assert sitl.t_s == pytest.approx(2.2) and _heartbeats(port) == 1


def test_a_stall_is_checked_and_stops_nothing_before_it_starts() -> None:
    with pytest.raises(ValueError, match="0 < stop < every"):
        Stall(stop_s=0.6, every_s=0.6)
    stall = Stall(stop_s=0.3, every_s=0.6, start_s=1.0)
    assert stall.reached_s(0.5) == 0.5 and stall.resumes_s(0.5) == 0.5
    assert stall.reached_s(1.45) == pytest.approx(1.3)
    assert stall.resumes_s(1.45) == pytest.approx(1.6)
    assert stall.reached_s(1.7) == 1.7 and stall.resumes_s(2.0) == pytest.approx(2.2)
