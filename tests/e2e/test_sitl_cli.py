"""The SITL program's command line: stdout contract, errors, vehicles, mocap, signing."""

from __future__ import annotations

import hashlib
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.e2e.sitl_proc import SitlProcess, Station, mavutil

pytestmark = pytest.mark.e2e


def test_bad_world_file_is_one_line_naming_file_and_exit_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[room]\nmin = [0, 0, 0]\nmax = "high"\n')
    proc = subprocess.run(
        [sys.executable, "-m", "sitl", "--tcp", "0", "--world", str(bad)],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "bad.toml" in lines[0]
    assert "Traceback" not in proc.stderr
    assert proc.stdout == ""


def test_signing_key_needs_copter4(tmp_path: Path) -> None:
    key = tmp_path / "key"
    key.write_text("a shared passphrase\n")
    proc = subprocess.run(
        [sys.executable, "-m", "sitl", "--tcp", "0", "--signing-key", str(key)],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1
    assert "copter4" in proc.stderr


def test_quadgcs_sitl_runs_vehicles_with_their_own_ports_and_mocap(tmp_path: Path) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "gcs", "sitl", "--tcp", "0", "--vehicles", "2", "--speedup", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=str(tmp_path),
    )
    try:
        assert proc.stdout is not None
        lines = []
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            line = proc.stdout.readline().strip()
            if line == "ready" or not line:
                break
            lines.append(line)
        assert [ln.split()[:2] for ln in lines] == [
            ["vehicle", "1"],
            ["vehicle", "2"],
            ["mocap", lines[2].split()[1]],
        ]
        assert all(ln.split()[-1].startswith("tcp:127.0.0.1:") for ln in lines)
        ports = [int(ln.rsplit(":", 1)[1]) for ln in lines]
        assert len(set(ports)) == 3
        v2 = mavutil.mavlink_connection(f"tcp:127.0.0.1:{ports[1]}", source_system=255)
        hb = v2.recv_match(type="HEARTBEAT", blocking=True, timeout=10)
        assert hb is not None and hb.get_srcSystem() == 2
        v2.close()
        mocap = mavutil.mavlink_connection(f"tcp:127.0.0.1:{ports[2]}", source_system=255)
        seen: set[int] = set()
        end = time.monotonic() + 10.0
        while len(seen) < 2 and time.monotonic() < end:
            m = mocap.recv_match(type="ATT_POS_MOCAP", blocking=True, timeout=1)
            if m is not None:
                assert m.get_srcSystem() == 200
                seen.add(m.get_srcComponent())
        mocap.close()
        assert seen == {1, 2}
    finally:
        proc.terminate()
        assert proc.wait(timeout=10) == 0


def test_a_client_that_reconnects_is_served_again(tmp_path: Path) -> None:
    sitl = SitlProcess(["--tcp", "0", "--speedup", "2"], tmp_path)
    try:
        host, port = sitl.endpoint(1, "tcp").split(":")
        raw = socket.create_connection((host, int(port)), timeout=5)
        raw.sendall(b"\x00\xff garbage \xfe\x05" * 20)
        raw.close()
        st = Station(f"tcp:{host}:{port}", mavlink1=True)
        try:
            st.wait_type("HEARTBEAT", lambda m: True, 10.0)
            st.request_streams(5)
            st.wait_type("ATTITUDE", lambda m: True, 10.0)
        finally:
            st.close()
        st = Station(f"tcp:{host}:{port}", mavlink1=True)
        try:
            st.wait_type("ATTITUDE", lambda m: True, 10.0)  # stream rates survive
        finally:
            st.close()
    finally:
        assert sitl.stop() == 0


def test_copter4_signing_refuses_unsigned_overrides(tmp_path: Path) -> None:
    keyfile = tmp_path / "key"
    keyfile.write_text("indoor quad passphrase\n")
    key = hashlib.sha256(b"indoor quad passphrase").digest()
    sitl = SitlProcess(
        ["--tcp", "0", "--profile", "copter4", "--signing-key", str(keyfile), "--speedup", "2"],
        tmp_path,
    )
    st = Station(f"tcp:{sitl.endpoint(1, 'tcp')}", mavlink1=False)
    try:
        st.conn.setup_signing(key, sign_outgoing=True)
        st.request_streams(5)
        st.wait_type("RC_CHANNELS", lambda m: True, 10.0)
        st.conn.mav.signing.sign_outgoing = False
        st.conn.mav.signing.secret_key = None  # now unsigned
        st.overrides = True
        st.sticks[2] = 1600
        deadline = time.monotonic() + 1.5
        while time.monotonic() < deadline:
            msg = st.wait_type("RC_CHANNELS", lambda m: True, 5.0)
            assert msg.chan3_raw == 1000  # refused
        st.conn.setup_signing(key, sign_outgoing=True)
        st.wait_type("RC_CHANNELS", lambda m: m.chan3_raw == 1600, 5.0)
    finally:
        st.close()
        assert sitl.stop() == 0


def test_udp_endpoint_sends_to_the_station_and_answers_it(tmp_path: Path) -> None:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.settimeout(0.5)
    port = sock.getsockname()[1]
    sitl = SitlProcess(["--tcp", "0", "--udp", f"127.0.0.1:{port}", "--speedup", "2"], tmp_path)
    mav = mavutil.mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    mav.robust_parsing = True
    try:
        assert sitl.endpoint(1, "udp") == f"127.0.0.1:{port}"
        kinds: set[str] = set()
        deadline = time.monotonic() + 15.0
        asked = False
        while "ATTITUDE" not in kinds and time.monotonic() < deadline:
            try:
                data, addr = sock.recvfrom(65536)
            except TimeoutError:
                continue
            kinds |= {m.get_type() for m in mav.parse_buffer(data) or []}
            if "HEARTBEAT" in kinds and not asked:
                req = mav.request_data_stream_encode(1, 1, 0, 5, 1).pack(mav, force_mavlink1=True)
                sock.sendto(req, addr)  # answered to whoever talks to it
                asked = True
        assert {"HEARTBEAT", "ATTITUDE"} <= kinds
    finally:
        sock.close()
        assert sitl.stop() == 0
