"""Lockstep flights: the station and the bundled SITL in one process on one simulated clock.

The flight is `quadgcs fly`'s own (session, supervisor, estimator, recorder); only the clock and
the link's medium differ, so a seed must give the same recording every time.
"""

from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path

import numpy as np
import pytest

from gcs.cli import build_parser, main
from gcs.commands.fly import fly
from gcs.lockstep_session import LOCKSTEP_EPOCH_NS
from logs import open_recording


def _fly(*argv: str) -> dict:
    return fly(build_parser().parse_args(["fly", "--lockstep", *argv]))


def _gcs_topics(path: Path) -> dict[str, tuple[int, str]]:
    """Per /gcs/ topic: message count and a digest of every (log time, payload)."""
    rec = open_recording(path)
    digests: dict[str, tuple[int, hashlib._Hash]] = {}
    for topic, log_ns, data in rec.raw_messages():
        if not topic.startswith("/gcs/"):
            continue
        n, h = digests.get(topic, (0, hashlib.sha256()))
        h.update(log_ns.to_bytes(8, "little"))
        h.update(data)
        digests[topic] = (n + 1, h)
    return {t: (n, h.hexdigest()) for t, (n, h) in digests.items()}


# Pinned to copter4 (whole-centimetre rangefinder): this test is about determinism. On apm25 the
# real 3.2.1 analog sonar's 6 cm steps put this hold at 0.088 m RMS (seed 5, #32).
COPTER4 = ("--profile", "copter4", "--fix-failsafe")


def test_a_seed_flies_the_same_flight_bit_for_bit(tmp_path: Path) -> None:
    c0 = time.process_time()
    first = _fly(*COPTER4, "--seed", "5", "--hold", "3", "-o", str(tmp_path / "a.mcap"))
    cpu_s = time.process_time() - c0
    second = _fly(*COPTER4, "--seed", "5", "--hold", "3", "-o", str(tmp_path / "b.mcap"))
    other = _fly(*COPTER4, "--seed", "6", "--hold", "3", "-o", str(tmp_path / "c.mcap"))
    a, b, c = (_gcs_topics(tmp_path / f"{n}.mcap") for n in "abc")
    for topic in ("/gcs/estimate", "/gcs/rc_override", "/gcs/tick", "/gcs/supervisor",
                  "/gcs/alt_controller", "/gcs/events", "/gcs/setup"):
        assert a[topic][0] > 0, topic
    assert a == b
    assert {**first, "recording": None} == {**second, "recording": None}
    # the test would notice: another seed is another flight
    assert a["/gcs/estimate"] != c["/gcs/estimate"]
    assert other["rms_error_m"] != first["rms_error_m"]
    # scored against the truth endpoint's 50 Hz reports, as over TCP
    assert first["error_source"] == "truth" and first["truth_rate_hz"] == pytest.approx(50, 0.05)
    assert first["rms_error_m"] < 0.05
    # a lockstep flight of ~25 simulated seconds is CPU-bound, not paced by the wall clock
    assert cpu_s < 10.0


def test_a_lockstep_flight_never_takes_real_time_priority() -> None:
    policy = os.sched_getscheduler(0) if hasattr(os, "sched_getscheduler") else 0
    _fly("--seed", "1", "--hold", "1", "--no-record")
    # a CPU-bound loop at SCHED_FIFO would starve the machine; the TCP loop may have it
    if hasattr(os, "sched_getscheduler"):
        assert os.sched_getscheduler(0) == policy


def test_the_recording_sits_on_the_fixed_lockstep_timeline(tmp_path: Path) -> None:
    _fly("--seed", "1", "--hold", "1", "-o", str(tmp_path / "f.mcap"))
    rec = open_recording(tmp_path / "f.mcap")
    assert int(rec.metadata["anchor_ns"]) == LOCKSTEP_EPOCH_NS
    # simulated time starts at zero with the SITL: the flight ends within a minute of it
    assert rec.start_ns >= LOCKSTEP_EPOCH_NS
    assert 10 * 10**9 < rec.end_ns - LOCKSTEP_EPOCH_NS < 60 * 10**9


@pytest.mark.parametrize("flag", [["--connect", "tcp:127.0.0.1:5760"], ["--serial"],
                                  ["--speedup", "2"], ["--foxglove", "0"]])
def test_lockstep_refuses_what_it_cannot_fly(flag: list[str],
                                             capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fly", "--lockstep", "--no-record", *flag]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"quadgcs fly: --lockstep: {flag[0]} cannot be used with it")


def test_a_fault_hits_only_the_vehicles_it_names() -> None:
    from gcs.errors import UsageError
    from gcs.lockstep import LockstepOptions
    from lab.lockstep import BundledLockstep

    sim = BundledLockstep(LockstepOptions(vehicles=2, faults={
        "fade": "down", "fade_start_s": 0.0, "fade_s": 100.0, "vehicles": [2]}))
    try:
        for port in sim.ports.values():
            port.connect()
        sim.sitl.advance_to(3.0)
        assert sim.ports[1].lost_frames == (0, 0) and sim.ports[1].read(1 << 20)
        assert sim.ports[2].lost_frames[0] > 0 and not sim.ports[2].read(1 << 20)
    finally:
        sim.close()
    for bad in ([3], [], "two", [True]):
        with pytest.raises(UsageError, match="faults' vehicles") as err:
            BundledLockstep(LockstepOptions(vehicles=2, faults={"fade": "both",
                                                                "vehicles": bad}))
        assert "\n" not in str(err.value)


def test_link_faults_are_refused_off_lockstep(tmp_path: Path) -> None:
    from gcs.errors import UsageError
    from gcs.mission.options import RunOptions
    from gcs.mission.runner import run_mission
    from gcs.mission.spec import load_mission

    mission = Path(__file__).resolve().parents[2] / "missions" / "epbha_table.toml"
    with pytest.raises(UsageError, match="lockstep only"):
        run_mission(load_mission(mission), RunOptions(output=tmp_path, link_faults={
            "fade": "both"}), None)


@pytest.mark.parametrize("seed", [4, 7])
def test_a_lossy_radio_still_reads_the_preflight_parameters_and_flies(seed: int) -> None:
    """A fifth of the frames lost both ways from power-on: every parameter request and its
    answer must get through one of the tries before the pre-flight deadline. (Tried once a
    second, these seeds lost every try of one parameter and the flight never armed.)"""
    from gcs.commands.fly import fly_session
    from gcs.flight import FlightPlan
    from gcs.lockstep_session import LockstepSession
    from gcs.station.session import SessionOptions

    options = SessionOptions(command="fly", profile="apm25", seed=seed, record=False)
    with LockstepSession(options, faults={"loss": 0.2}) as session:
        summary = fly_session(session, FlightPlan(alt_m=1.0, hold_s=5.0), pilot_signals=False)
    assert summary["status"] == "ok", summary
    assert summary["lost_messages"] > 0  # the radio did lose frames


@pytest.mark.parametrize(
    "seed",
    [
        pytest.param(4, marks=pytest.mark.xfail(strict=True, reason=(
            "#32: over 3.2.1's analog sonar (6 cm steps, nothing used below 20 cm) the "
            "station's hold strays 0.28 m through the minute of loss (floor 0.1 m)"))),
        pytest.param(15, marks=pytest.mark.xfail(strict=True, reason=(
            "#32: over 3.2.1's analog sonar (6 cm steps, nothing used below 20 cm) the "
            "station's hold strays 0.61 m through the minute of loss (floor 0.1 m)"))),
    ],
)
def test_a_hold_rides_out_a_minute_of_a_lossy_radio(seed: int) -> None:
    """A third of the frames lost both ways for 60 s, 30 s into a 1 m hold (the fault suite's
    30 % loss with 5 % bit flips: a flipped frame fails its checksum, so it is lost too): the
    vehicle stays within ±0.1 m by truth. These seeds strayed 0.16 and 0.45 m when a reading
    after lost frames was taken for a late echo and the estimator's own velocity error made
    the sonar's repeats look stale (bench/lossy_hold.py: 20 seeds per profile)."""
    from gcs.commands.fly import fly_session
    from gcs.flight import FlightPlan
    from gcs.lockstep_session import LockstepSession
    from gcs.station.session import SessionOptions

    start_s, lasting_s = 40.0, 60.0
    options = SessionOptions(command="fly", profile="apm25", seed=seed, record=False)
    faults = {"loss": 1.0 - 0.7 * 0.95, "loss_start_s": start_s, "loss_s": lasting_s}
    with LockstepSession(options, faults=faults) as session:
        summary = fly_session(session, FlightPlan(alt_m=1.0, hold_s=95.0), pilot_signals=False)
        series = session.first.truth_series()
    assert summary["status"] == "ok", summary
    assert summary["lost_messages"] > 1000
    assert series is not None
    during = (series.t_s >= start_s) & (series.t_s < start_s + lasting_s)
    assert during.sum() > 0.9 * lasting_s * 10  # truth at 10 Hz or more, the whole minute
    assert np.max(np.abs(series.alt_m[during] - 1.0)) <= 0.1
