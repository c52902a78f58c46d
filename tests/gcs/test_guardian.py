"""The guardian process against a small MAVLink vehicle on a real TCP socket or pseudo-terminal.

The station's side is a real `VehicleLink`; the guardian is the real
`python -m gcs.station.guardian`.
A station process that dies closes its end of the guardian's socket without a word: the tests
close it the same way (the kernel does nothing more when the process is killed).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from types import SimpleNamespace

import pytest

from firmware_link import VehicleLink
from firmware_link.records import FlightMode, LinkEvent, LinkEventKind
from gcs.station.guardian import Guardian, GuardianSetup
from gcs.supervisor import SupervisorState
from tests.firmware_link.peer import FakeVehicle, wait_until
from worldfile import key_from_passphrase

KEY = key_from_passphrase("quadgcs guardian key")
HOVER_US = 1480
EXIT_S = 10.0


def _snapshot(state: SupervisorState, throttle_us: int = HOVER_US) -> SimpleNamespace:
    return SimpleNamespace(state=state, safe_throttle_us=throttle_us)


@contextlib.contextmanager
def _guarded(profile: str, *, serial: bool = False, key: bytes | None = None,
             speedup: float = 1.0) -> Iterator[tuple[FakeVehicle, VehicleLink, Guardian]]:
    """An armed vehicle in STABILIZE, the station's link to it, and the link's guardian."""
    v = FakeVehicle(profile, serial=serial, signing_key=key).start()
    link = VehicleLink.open(v.url, signing_key=key, identify=False)
    v.state.armed, v.state.mode = True, int(FlightMode.STABILIZE)
    guardian = Guardian.start(link, GuardianSetup(link.spec, link.firmware, link.target_system,
                                                  link.target_component, key, 0.025, speedup))
    assert guardian is not None
    try:
        yield v, link, guardian
    finally:
        guardian.stand_down()
        link.close()
        v.stop()


@pytest.fixture(params=[("apm25", False, None), ("copter4", False, None),
                        ("copter4", False, KEY), ("apm25", True, None)],
                ids=["apm25-tcp", "copter4-tcp", "copter4-tcp-signed", "apm25-serial"])
def flying(request: pytest.FixtureRequest) -> Iterator[tuple[FakeVehicle, VehicleLink, Guardian]]:
    """An armed vehicle in STABILIZE, its link, and the link's guardian."""
    profile, serial, key = request.param
    with _guarded(profile, serial=serial, key=key) as rig:
        yield rig


def _die(guardian: Guardian) -> int:
    """The station's process is gone: its end of the socket closes. The guardian's exit."""
    guardian._sock.close()
    return guardian._proc.wait(EXIT_S)


def _die_and_disarm(v: FakeVehicle, guardian: Guardian, stay_s: float = 0.0) -> int:
    """The station dies; once the guardian has LAND and sends the throttle at minimum, the
    fake vehicle stays armed `stay_s` more (landing, then 3.2.1 landed waiting for the stick),
    then disarms as 3.2.1 does after LAND with the throttle at minimum. The guardian's exit."""
    guardian._sock.close()
    assert wait_until(lambda: v.state.mode == int(FlightMode.LAND)
                      and bool(v.state.overrides) and v.state.overrides[-1][2][2] == 1000,
                      EXIT_S)
    if stay_s:
        # the vehicle stays armed while the guardian sends this many minimum-throttle frames
        # (one per 25 ms tick): it must not leave in them
        start = len(v.state.overrides)
        assert wait_until(lambda: len(v.state.overrides) - start >= stay_s / 0.025 / 2,
                          EXIT_S + stay_s)
        assert guardian._proc.poll() is None
    v.state.armed = False
    return guardian._proc.wait(EXIT_S)


def test_a_station_that_dies_flying_has_the_vehicle_landed(flying) -> None:
    """Landed, it stays (throttle minimum, heartbeats) until the vehicle is seen disarmed: until
    #32 it released the overrides once LAND showed and went quiet, and the real 3.2.1, still
    armed on the floor, met its GCS failsafe, whose RTL took it back up to 14 m."""
    v, _link, guardian = flying
    guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
    before = len(v.state.overrides)
    assert _die_and_disarm(v, guardian, stay_s=2.5) == 0
    assert v.state.mode == int(FlightMode.LAND)
    assert v.state.refused == 0  # a signed link stays signed
    sent = [chans for _, _, chans in v.state.overrides[before:]]
    assert sent and sent[0][:4] == (1500, 1500, HOVER_US, 1500)  # level, hover, until LAND
    firsts = [i for i, c in enumerate(sent) if c[2] == 1000]
    # then level at minimum, nothing released, until the vehicle is seen disarmed
    assert all(c[:4] == (1500, 1500, 1000, 1500) for c in sent[firsts[0]:-1])
    assert len(sent) - firsts[0] >= 2.0 / 0.025 / 2  # through the 2.5 s it stayed armed
    assert sent[-1] == (0,) * 8  # then handed back to the radio


def test_a_guardian_keeps_heartbeats_while_the_landed_vehicle_stays_armed() -> None:
    with _guarded("apm25") as (v, _link, guardian):
        guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
        guardian._sock.close()
        assert wait_until(lambda: v.state.mode == int(FlightMode.LAND), EXIT_S)
        hb0 = v.state.gcs_heartbeats
        # three more heartbeats (1 Hz) from a guardian that has not left the armed vehicle
        assert wait_until(lambda: v.state.gcs_heartbeats - hb0 >= 3, EXIT_S + 3.0)
        assert guardian._proc.poll() is None
        v.state.armed = False
        assert guardian._proc.wait(EXIT_S) == 0


def test_a_station_that_stands_down_leaves_the_link_alone(flying) -> None:
    v, _link, guardian = flying
    guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
    before = list(v.state.rx_types)
    guardian.stand_down()
    assert guardian._proc.returncode == 0
    assert v.state.rx_types[len(before):].count("SET_MODE") == 0
    assert v.state.mode == int(FlightMode.STABILIZE)


@pytest.mark.parametrize("state", [SupervisorState.DISARMED, SupervisorState.RELEASED,
                                   SupervisorState.SILENT, SupervisorState.KILLED])
def test_a_station_that_dies_not_flying_the_vehicle_adds_nothing(flying, state) -> None:
    """Disarmed, let go, silent on purpose (the vehicle's failsafe is to act) or killed: the
    vehicle is not the station's to land."""
    v, _link, guardian = flying
    guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
    guardian.on_snapshot(_snapshot(state))
    before = len(v.state.rx_types)
    assert _die(guardian) == 0
    assert "SET_MODE" not in v.state.rx_types[before:]
    assert v.state.mode == int(FlightMode.STABILIZE)


@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_a_vehicle_that_never_answers_is_left_to_its_failsafe(profile: str) -> None:
    """(At 3x: the guardian's 3 s are the vehicle's, here a SITL's three times faster.)"""
    with _guarded(profile, speedup=3.0) as (v, _link, guardian):
        v.state.heartbeats = False
        guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
        t0 = time.monotonic()
        assert _die(guardian) == 1  # LAND asked for 3 s, never shown: it goes silent
        assert time.monotonic() - t0 >= 0.95
        assert v.state.mode == int(FlightMode.LAND)  # asked all the same
        last = v.state.overrides[-1][2]
        assert last[2] == HOVER_US  # not released: 4.x would drop to the radio's minimum


def _restarted(v: FakeVehicle) -> bool:
    try:
        v.restart()
    except OSError:
        return False
    return True


def test_a_reopened_link_is_handed_over_again() -> None:
    """The station's TCP link reconnects (the vehicle end restarted): the guardian must hold the
    new connection, not the dead one, though the descriptor may have the same number."""
    with _guarded("copter4") as (v, link, guardian):
        guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
        v.crash()
        assert wait_until(lambda: any(
            isinstance(r, LinkEvent) and r.kind is LinkEventKind.RECONNECTING
            for r in link.poll()), 5.0)
        guardian.on_snapshot(_snapshot(SupervisorState.HOLD))  # the link was dropped
        # the port is free once the guardian has closed its copy of the dead connection
        assert wait_until(lambda: _restarted(v), 5.0)
        assert wait_until(lambda: any(
            isinstance(r, LinkEvent) and r.kind is LinkEventKind.RECONNECTING
            and "reopened" in r.detail
            for r in link.poll()), 10.0)
        v.state.armed = True
        guardian.on_snapshot(_snapshot(SupervisorState.HOLD))
        assert _die_and_disarm(v, guardian) == 0
        assert v.state.mode == int(FlightMode.LAND)


def test_a_guardian_that_cannot_start_is_one_line_and_no_guardian(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    v = FakeVehicle("apm25").start()
    link = VehicleLink.open(v.url, identify=False)
    try:
        monkeypatch.setattr("sys.executable", "/nonexistent/python3")
        guardian = Guardian.start(link, GuardianSetup(link.spec, link.firmware, 1, 1, None,
                                                      0.025, 1.0))
        assert guardian is None
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("guardian: not started (")
        assert "own failsafe" in err[0]
    finally:
        link.close()
        v.stop()
