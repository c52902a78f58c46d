"""A small MAVLink vehicle for link tests: heartbeats, streams, arming, modes, parameters.

It stands in for the autopilot board (the one thing tests may mock) on a real TCP socket or a
real pseudo-terminal, in a thread. It speaks MAVLink 1 ("apm25", as ArduCopter 3.2.1) or
MAVLink 2 ("copter4", as ArduCopter 4.7), answering as the real firmware does where the station
tells them apart: 3.2.1 refuses arming with UNSUPPORTED and a "PreArm:" text, refuses
AUTOPILOT_VERSION requests and sends its version banner in reply to PARAM_REQUEST_LIST; 4.7
refuses with FAILED, answers AUTOPILOT_VERSION and names its GCS id MAV_GCS_SYSID. `wire_v1`
makes a copter4 speak MAVLink 1 (a 4.x port set to MAVLink 1).
"""

from __future__ import annotations

import os
import select
import socket
import threading
import time
import tty
from dataclasses import dataclass, field

from pymavlink.dialects.v10 import ardupilotmega as mav1
from pymavlink.dialects.v20 import ardupilotmega as mav2

ATTITUDE_ID = 30
V4_7_DEV = (4 << 24) | (7 << 16) | (0 << 8) | 0  # flight_sw_version of 4.7.0-dev
GIT_HASH = b"d2e4299f"
PARAMS = {
    "apm25": {"SYSID_MYGCS": 255.0, "FS_GCS_ENABLE": 1.0, "THR_MID": 500.0, "THR_MIN": 130.0},
    "copter4": {"MAV_GCS_SYSID": 255.0, "FS_GCS_ENABLE": 0.0, "MOT_THST_HOVER": 0.39,
                "ARMING_CHECK": 1.0, "ATC_RAT_RLL_P": 0.135},
}
INT_PARAMS = {"SYSID_MYGCS", "MAV_GCS_SYSID", "FS_GCS_ENABLE", "THR_MID", "THR_MIN",
              "ARMING_CHECK"}
BANNERS = {"apm25": ("ArduCopter V3.2.1", "Frame: QUAD"),
           "copter4": ("ArduCopter V4.7.0-dev (d2e4299f)", "Frame: QUAD/X")}
STREAM_MESSAGES = {10: ("ATTITUDE",), 1: ("RAW_IMU",), 12: ("RANGEFINDER", "DISTANCE_SENSOR")}


class _Sink:
    def write(self, data: bytes) -> None:
        pass


@dataclass
class PeerState:
    """What the fake vehicle saw and is."""

    armed: bool = False
    mode: int = 0
    arm_refusal: str = ""  # non-empty: refuse arming with this STATUSTEXT
    arm_refusal_silent: bool = False  # refuse arming with no text (3.2.1, throttle not low)
    arm_refusals_left: int = -1  # with arm_refusal: refuse this many times, then arm (-1: always)
    answers_version: bool = True  # copter4 answers AUTOPILOT_VERSION requests
    sends_banner: bool = True  # the version banner in reply to PARAM_REQUEST_LIST
    heartbeats: bool = True  # False: streams and replies go on, HEARTBEAT does not
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)  # clamps PARAM_SET
    params: dict[str, float] = field(default_factory=dict)
    overrides: list[tuple[int, int, tuple[int, ...]]] = field(default_factory=list)  # sys, len
    rx_types: list[str] = field(default_factory=list)
    gcs_heartbeats: int = 0
    refused: int = 0
    rates_hz: dict[str, float] = field(default_factory=dict)


class FakeVehicle:
    """A vehicle on a TCP server socket or a pty master, served from a thread."""

    def __init__(
        self,
        profile: str = "copter4",
        *,
        serial: bool = False,
        sysid: int = 1,
        signing_key: bytes | None = None,
        companion: bool = True,
        wire_v1: bool = False,
        rcvbuf: int | None = None,
    ) -> None:
        self.profile = profile
        self.sysid = sysid
        self.state = PeerState(params=dict(PARAMS[profile]))
        self.paused = threading.Event()
        self.stall_rx = threading.Event()  # set: stop reading what the station sends
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self.companion = companion
        self._v1 = profile == "apm25" or wire_v1
        self._mav = mav2.MAVLink(_Sink(), sysid, 1)
        self._enc1 = mav1.MAVLink(_Sink(), sysid, 1)
        self._comp = mav2.MAVLink(_Sink(), sysid, 158)
        self._parser = mav2.MAVLink(_Sink(), 0, 0)
        self._parser.robust_parsing = True
        if signing_key is not None:
            for m in (self._mav, self._comp, self._parser):
                m.signing.secret_key = signing_key
                m.signing.sign_outgoing = True
                m.signing.timestamp = int((time.time() - 1420070400) * 100000)
        self._server: socket.socket | None = None
        self._client: socket.socket | None = None
        self._master = -1
        self.url = ""
        if serial:
            self._master, slave = os.openpty()
            tty.setraw(slave)
            self.url = os.ttyname(slave)
            self._slave = slave
        else:
            self._server = socket.socket()
            self._server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if rcvbuf is not None:  # a small window fills fast when the reader stalls
                self._server.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
            self._server.bind(("127.0.0.1", 0))
            self._server.listen(4)
            self.port = self._server.getsockname()[1]
            self.url = f"tcp:127.0.0.1:{self.port}"
        self._thread = threading.Thread(target=self._run, daemon=True)

    # -- control
    def start(self) -> FakeVehicle:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        for s in (self._client, self._server):
            if s is not None:
                s.close()
        if self._master >= 0:
            os.close(self._master)
            os.close(self._slave)

    def crash(self) -> None:
        """Vanish as a SITL that died: close the connection and the listening port."""
        self.paused.set()
        with self._lock:
            for s in (self._client, self._server):
                if s is not None:
                    s.close()
            self._client = self._server = None

    def restart(self) -> None:
        """Listen again on the same port and speak again."""
        server = socket.socket()
        server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        server.bind(("127.0.0.1", self.port))
        server.listen(4)
        with self._lock:
            self._server = server
        self.paused.clear()

    def inject(self, data: bytes) -> None:
        """Write raw bytes to the station (garbage, foreign frames)."""
        self._write(data)

    # -- io
    def _write(self, data: bytes) -> None:
        with self._lock:
            try:
                if self._master >= 0:
                    os.write(self._master, data)
                elif self._client is not None:
                    self._client.sendall(data)
            except OSError:
                pass

    def _send(self, msg, comp: bool = False) -> None:
        if self._v1:
            enc = self._enc1
            frame = msg.pack(enc, force_mavlink1=True)
            enc.seq = (enc.seq + 1) % 256
        else:
            enc = self._comp if comp else self._mav
            frame = msg.pack(enc)
            enc.seq = (enc.seq + 1) % 256
        self._write(frame)

    def _enc(self):
        return self._enc1 if self._v1 else self._mav

    def _fds(self) -> list[int]:
        if self._master >= 0:
            return [self._master]
        with self._lock:
            return [s.fileno() for s in (self._server, self._client) if s is not None]

    def _run(self) -> None:
        next_hb = 0.0
        next_msg: dict[str, float] = {}
        next_comp = 0.0
        t0 = time.monotonic()
        while not self._stop.is_set():
            fds = self._fds()
            if self.stall_rx.is_set():
                with self._lock:
                    server = self._server
                fds = [server.fileno()] if server is not None and self._master < 0 else []
            try:
                readable = select.select(fds, [], [], 0.001)[0] if fds else []
            except (OSError, ValueError):
                continue  # a socket closed under us by crash()
            if not fds:
                self._stop.wait(0.005)
            for fd in readable:
                with self._lock:
                    server, client = self._server, self._client
                if server is not None and fd == server.fileno():
                    try:
                        client, _ = server.accept()
                    except OSError:
                        continue
                    client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                    with self._lock:
                        if self._client is not None:
                            self._client.close()
                        self._client = client
                    next_hb = 0.0  # greet a new station at once
                    continue
                try:
                    if self._master >= 0:
                        data = os.read(fd, 4096)
                    elif client is not None and fd == client.fileno():
                        data = client.recv(4096)
                    else:
                        continue
                except OSError:
                    data = b""
                if not data:
                    with self._lock:
                        if self._client is not None:
                            self._client.close()
                            self._client = None
                    continue
                for msg in self._parser.parse_buffer(data) or ():
                    self._handle(msg)
            now = time.monotonic()
            if self.paused.is_set():
                continue
            if now >= next_hb and self.state.heartbeats:
                next_hb = now + 1.0
                base = 81 | (128 if self.state.armed else 0)
                self._send(self._enc().heartbeat_encode(2, 3, base, self.state.mode, 3, 3))
            for name, hz in list(self.state.rates_hz.items()):
                if hz <= 0:
                    continue
                due = next_msg.get(name, now)
                if now >= due:
                    # Keep the cadence: schedule from the due time, not from now.
                    next_msg[name] = max(due + 1.0 / hz, now - 0.05)
                    self._send_stream(name, now - t0)
            if self.companion and self.profile == "copter4" and now >= next_comp:
                next_comp = now + 0.1
                self._send(
                    self._comp.distance_sensor_encode(0, 20, 50, 35, 0, 0, 0, 0), comp=True
                )
                self._send(self._comp.named_value_float_encode(0, b"RAD_CPS", 12.5), comp=True)

    def _send_stream(self, name: str, t: float) -> None:
        enc = self._enc()
        if name == "ATTITUDE":
            self._send(enc.attitude_encode(int(t * 1000), 0.01, -0.02, 1.0, 0.0, 0.0, 0.0))
        elif name == "RAW_IMU":
            self._send(enc.raw_imu_encode(int(t * 1e6), 10, -5, -1000, 1, 2, 3, 0, 0, 0))
        elif name == "RANGEFINDER" and self.profile == "apm25":
            self._send(enc.rangefinder_encode(0.75, 0.0))
        elif name == "DISTANCE_SENSOR" and self.profile == "copter4":
            self._send(enc.distance_sensor_encode(int(t * 1000), 2, 400, 75, 1, 0, 25, 0))

    def _ack(self, command: int, result: int) -> None:
        self._send(self._enc().command_ack_encode(command, result))

    def _handle(self, msg) -> None:
        kind = msg.get_type()
        st = self.state
        if kind == "BAD_DATA":
            if "signature" in str(getattr(msg, "reason", "")):
                st.refused += 1
            return
        st.rx_types.append(kind)
        enc = self._enc()
        if kind == "HEARTBEAT":
            if msg.type == 6:
                st.gcs_heartbeats += 1
        elif kind == "RC_CHANNELS_OVERRIDE":
            st.overrides.append(
                (msg.get_srcSystem(), len(msg.get_payload()), tuple(
                    getattr(msg, f"chan{i}_raw") for i in range(1, 9)))
            )
        elif kind == "SET_MODE":
            st.mode = msg.custom_mode
            self._ack(11, 0)  # both firmwares acknowledge SET_MODE as "command" 11
        elif kind == "REQUEST_DATA_STREAM":
            for name in STREAM_MESSAGES.get(msg.req_stream_id, ()):
                st.rates_hz[name] = float(msg.req_message_rate) if msg.start_stop else 0.0
        elif kind == "COMMAND_LONG":
            if msg.command == 400:
                if (msg.param1 == 1 and (st.arm_refusal or st.arm_refusal_silent)
                        and msg.param2 != 2989 and st.arm_refusals_left != 0):
                    st.arm_refusals_left -= 1 if st.arm_refusals_left > 0 else 0
                    if st.arm_refusal:
                        self._send(enc.statustext_encode(3, st.arm_refusal.encode()))
                    # 3.2.1 answers a refused arm UNSUPPORTED, 4.x FAILED
                    self._ack(400, 3 if self.profile == "apm25" else 4)
                    return
                st.armed = msg.param1 == 1
                self._ack(400, 0)
                self._send(enc.heartbeat_encode(2, 3, 81 | (128 * st.armed), st.mode, 3, 3))
            elif msg.command in (512, 520) and self.profile == "copter4" and st.answers_version:
                if msg.command == 512 and int(msg.param1) != 148:
                    self._ack(512, 4)
                    return
                self._ack(msg.command, 0)
                self._send(enc.autopilot_version_encode(
                    0, V4_7_DEV, 0, 0, 0, list(GIT_HASH), [0] * 8, [0] * 8, 0, 0, 0))
            elif msg.command == 511 and self.profile == "copter4":
                names = {30: "ATTITUDE", 27: "RAW_IMU", 132: "DISTANCE_SENSOR"}
                name = names.get(int(msg.param1))
                if name is None:
                    self._ack(511, 4)
                    return
                st.rates_hz[name] = 1e6 / msg.param2 if msg.param2 > 0 else 0.0
                self._ack(511, 0)
            else:
                self._ack(msg.command, 3)
        elif kind == "PARAM_REQUEST_READ":
            names = list(st.params)
            name = msg.param_id if msg.param_index < 0 else (
                names[msg.param_index] if msg.param_index < len(names) else None)
            if name in st.params:
                self._param(name)
        elif kind == "PARAM_SET":
            if msg.param_id in st.params:
                value = msg.param_value
                if msg.param_id in INT_PARAMS:
                    value = float(int(value))
                low, high = st.limits.get(msg.param_id, (-1e38, 1e38))
                st.params[msg.param_id] = min(high, max(low, value))
                self._param(msg.param_id)
        elif kind == "PARAM_REQUEST_LIST":
            if st.sends_banner:
                for text in BANNERS[self.profile]:
                    self._send(enc.statustext_encode(6, text.encode()))
            for name in st.params:
                self._param(name)

    def _param(self, name: str) -> None:
        names = list(self.state.params)
        self._send(
            self._enc().param_value_encode(
                name.encode(), self.state.params[name], 4 if name in INT_PARAMS else 9,
                len(names), names.index(name)
            )
        )


def wait_until(predicate, timeout_s: float = 3.0) -> bool:
    """Poll `predicate` until it holds or `timeout_s` passes; its last value."""
    deadline = time.monotonic() + timeout_s
    pause = threading.Event()
    while not predicate():
        if time.monotonic() >= deadline:
            return bool(predicate())
        pause.wait(0.005)
    return True
