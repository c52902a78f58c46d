"""The guardian: a small process that lands the vehicle if the station's process dies.

A station killed outright (SIGKILL, the OOM killer, a crash of the interpreter, a closed
terminal) cannot run its own landing: the autopilot then flies the last RC override open loop
until its own failsafe notices, 2 s on 3.2.1 and on 4.x with `FS_GCS_TIMEOUT` 2, and a hold's
last throttle a few tens of microseconds off hover carries the vehicle most of a metre in that
time. So every station on a real link (TCP, UDP or serial) starts a guardian beside it:

- The station hands it the link's open descriptor (over a Unix socket, `SCM_RIGHTS`, again
  whenever the link is reopened), who the vehicle is, and, each tick it changes, whether the
  vehicle may be flying under the station's control and its safe throttle (hover aloft,
  minimum on the floor).
- It reads nothing and sends nothing while the station lives: the link stays the station's.
- A station that stops in order tells it to leave (`stand_down`): the station lands and lets go
  by itself (`gcs.station.exit`), and the guardian adds nothing.
- A station that vanishes closes the socket without that word. If it was flying the vehicle,
  the guardian takes the link over at once and does what a dying station loop does: SET_MODE
  LAND with the safe throttle, level, until a heartbeat shows LAND or disarmed; then throttle
  minimum and heartbeats until a heartbeat shows it disarmed (3.2.1 disarms after LAND only with
  the throttle at minimum: a guardian that went quiet on the landed, armed vehicle had its GCS
  failsafe RTL it back up to 14 m), reported loudly every 30 s while it stays armed, and only
  then releases the overrides. With no heartbeat at all within 3 s (nothing heard) it goes
  silent, so the vehicle's own failsafe (set up before flight) acts. It says what it did on the
  station's stderr and exits.

The guardian ignores SIGINT and runs in its own session: a Ctrl-C or a hang-up meant for the
station reaches the station, whose exit the guardian then watches.
"""

from __future__ import annotations

import os
import pickle
import signal
import socket
import subprocess
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING

from firmware_link.connection import ConnectionSpec, Transport
from firmware_link.firmware import FirmwareInfo
from firmware_link.records import Heartbeat
from gcs.core.landing import lands_on_death
from gcs.station.exit import emergency_land, let_go, stay_until_disarmed
from gcs.station.types import StationSnapshot
from gcs.supervisor import SupervisorState

if TYPE_CHECKING:  # the guardian's process imports it where it opens its link
    from firmware_link.vehicle_link import VehicleLink

# A guardian just started is still importing pymavlink (1.0-1.3 s measured on a loaded 2-core
# machine) before it reads the word to leave: waited 1 s, it was killed (exit -9) instead
STAND_DOWN_WAIT_S = 5.0
MESSAGE_BYTES = 65536
THROTTLE_STEP_US = 2  # a safe throttle this much off what the guardian has is sent again
HANDED_OVER = (Transport.TCP, Transport.UDPIN, Transport.UDPOUT, Transport.SERIAL)


@dataclass(frozen=True, slots=True)
class GuardianSetup:
    """What the guardian needs to speak to the vehicle as the station did."""

    spec: ConnectionSpec
    firmware: FirmwareInfo
    target_system: int
    target_component: int
    signing_key: bytes | None
    period_s: float
    speedup: float


class GuardianGone(RuntimeError):
    """The guardian process is not there any more: the station flies without one."""


class Guardian:
    """The station's side: start the process, keep it informed, stand it down."""

    def __init__(self, link: VehicleLink, sock: socket.socket,
                 proc: subprocess.Popen[bytes]) -> None:
        self._link = link
        self._sock = sock
        self._proc = proc
        self._sent_link: int | None = None
        self._sent_peer: tuple[object, ...] | None = None
        self._sent_state: tuple[bool, int, str] | None = None
        self._gone = False

    @classmethod
    def start(cls, link: VehicleLink, setup: GuardianSetup) -> Guardian | None:
        """A guardian for `link`, or None for a link no other process can take over (an
        in-memory lockstep link)."""
        if setup.spec.transport not in HANDED_OVER:
            return None
        ours: socket.socket | None = None
        try:
            ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
            try:
                proc = subprocess.Popen(
                    [sys.executable, "-m", "gcs.station.guardian", str(theirs.fileno())],
                    pass_fds=(theirs.fileno(),), stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL, start_new_session=True)
            finally:
                theirs.close()
        except OSError as exc:  # the station flies as it did before there was a guardian
            if ours is not None:
                ours.close()
            _say(f"not started ({exc}): a station killed mid-air leaves the vehicle to its "
                 "own failsafe")
            return None
        ours.sendall(pickle.dumps(("setup", setup)))
        ours.setblocking(False)  # from here on the loop thread sends: it must never wait
        guardian = cls(link, ours, proc)
        guardian._send_handoff()
        return guardian

    def on_snapshot(self, snap: StationSnapshot) -> None:
        """A station listener: pass on what changed (the link's descriptor, whether the
        vehicle is the station's to land, its safe throttle). Raises GuardianGone once."""
        if self._gone:
            return
        self._send_handoff()
        state = (lands_on_death(snap.state), snap.safe_throttle_us, snap.state.value)
        last = self._sent_state
        changed = (last is None or state[0] != last[0] or state[2] != last[2]
                   or abs(state[1] - last[1]) >= THROTTLE_STEP_US)
        if changed and self._send(("state", *state)):
            self._sent_state = state

    def stand_down(self) -> None:
        """The station has let go by itself: the guardian leaves without a word."""
        if not self._gone:
            self._gone = True
            try:
                self._sock.setblocking(True)
                self._sock.sendall(pickle.dumps(("quit",)))
            except OSError:
                pass
        self._sock.close()
        try:
            self._proc.wait(STAND_DOWN_WAIT_S)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()

    def _send_handoff(self) -> None:
        handoff = self._link.handoff()
        if handoff is None:
            # dropped (being reopened): the guardian's copy must go too, or the dead
            # connection stays half open, its port taken, until the new one is handed over
            if self._sent_link is not None and self._send(("link", None)):
                self._sent_link = self._sent_peer = None
            return
        generation, fd, peer = handoff
        # by generation, not number: a reopened link may get the number of the one it replaced
        if ((generation, peer) != (self._sent_link, self._sent_peer)
                and self._send(("link", peer), fd)):
            self._sent_link, self._sent_peer = generation, peer

    def _send(self, message: tuple[object, ...], fd: int | None = None) -> bool:
        data = pickle.dumps(message)
        try:
            if fd is None:
                self._sock.send(data)
            else:
                socket.send_fds(self._sock, [data], [fd])
        except BlockingIOError:
            return False  # it reads slowly: the next tick sends the newest again
        except OSError as exc:
            self._gone = True
            code = self._proc.poll()
            raise GuardianGone(f"the guardian process is gone (exit {code}, {exc}): a station "
                               "that dies now leaves the vehicle to its own failsafe") from None
        return True


def _say(text: str) -> None:
    print(f"guardian: {text}", file=sys.stderr, flush=True)


def take_over(setup: GuardianSetup, fd: int, peer: tuple[object, ...] | None, throttle_us: int,
              state: str) -> int:
    """Land the vehicle of a station that died flying it; the exit status."""
    from firmware_link.transport import adopt_transport
    from firmware_link.vehicle_link import VehicleLink

    link = VehicleLink.adopt(setup.spec, adopt_transport(setup.spec, fd, peer), setup.firmware,
                             target_system=setup.target_system,
                             target_component=setup.target_component,
                             signing_key=setup.signing_key)
    _say(f"the station stopped with vehicle {setup.target_system} in {state}: asking for LAND "
         f"(throttle {throttle_us} us until it shows)")
    hb = emergency_land(link, throttle_us, setup.period_s, speedup=setup.speedup)
    if isinstance(hb, Heartbeat) and hb.armed:
        _say(f"vehicle {setup.target_system} in LAND: throttle minimum and heartbeats until it "
             "disarms")
        hb = stay_until_disarmed(link, throttle_us, setup.period_s, _say, speedup=setup.speedup)
        if not isinstance(hb, Heartbeat):
            link.close()
            _say(f"vehicle {setup.target_system} may still be armed: the link failed ({hb})")
            return 1
    if isinstance(hb, Heartbeat):
        text = let_go(link, SupervisorState.QUITTING, hb)
        link.close()
        _say(f"vehicle {setup.target_system} disarmed"
             f"{': ' + text if text else ', overrides released'}")
        return 0
    link.close()
    why = hb if isinstance(hb, str) else "no heartbeat showed LAND within 3 s"
    _say(f"{why}: silent now, vehicle {setup.target_system}'s own failsafe acts")
    return 1


def main(argv: list[str]) -> int:
    """Wait on the station's socket (descriptor `argv[0]`); take over if it dies flying."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    sock = socket.socket(fileno=int(argv[0]))
    import firmware_link.vehicle_link  # noqa: F401  # now, not in the seconds that count

    setup: GuardianSetup | None = None
    fd: int | None = None
    peer: tuple[object, ...] | None = None
    flying, throttle_us, state = False, 1000, "?"
    while True:
        try:
            data, fds, _, _ = socket.recv_fds(sock, MESSAGE_BYTES, 1)
        except OSError:
            data, fds = b"", []
        if not data:
            break
        message = pickle.loads(data)
        if message[0] == "setup":
            setup = message[1]
        elif message[0] == "link":
            if fd is not None:
                os.close(fd)  # dropped or reopened: the old descriptor is the station's past
            fd, peer = (fds[0], message[1]) if fds else (None, None)
        elif message[0] == "state":
            flying, throttle_us, state = message[1], message[2], message[3]
        elif message[0] == "quit":
            return 0
    if not flying or setup is None:
        return 0
    if fd is None:
        _say(f"the station stopped with vehicle {setup.target_system} in {state} while its link "
             "was being reopened: nothing to take over, the vehicle's own failsafe acts")
        return 1
    return take_over(setup, fd, peer, throttle_us, state)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
