"""`replay --rerun`: a flight recorded to a real MCAP file, re-run through fresh instances."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from firmware_link.records import Imu, Rangefinder
from gcs import params_json, topics
from gcs.cli import main
from gcs.clock import SimClock
from gcs.config import EstimatorKind, StationConfig
from gcs.core.inputs import TickRecord
from gcs.errors import UsageError
from gcs.rerun import (
    RerunReport,
    apply_overrides,
    changed_parameters,
    compare,
    load_flight,
    parse_gains,
    rerun,
)
from gcs.station.station import Station, StationSetup
from logs import Recorder, open_recording
from tests.gcs.test_station import FakeBoard


class NoisyBoard(FakeBoard):
    """The fake board with seeded sensor noise, two IMU samples a poll and sonar outliers, so
    the rerun has averaging, gating and extra sonar updates to reproduce."""

    def __init__(self, clock: SimClock, rng: np.random.Generator) -> None:
        super().__init__(clock, hover_true=0.55)
        self.rng = rng

    def poll(self) -> list[Any]:
        out: list[Any] = []
        for r in super().poll():
            if isinstance(r, Imu):
                for _ in range(2):
                    acc = tuple(float(a + self.rng.normal(0.0, 0.4)) for a in r.acc_b)
                    out.append(Imu(r.t_s, r.sysid, acc, r.gyro_b, r.source))
            elif isinstance(r, Rangefinder) and r.valid:
                d = r.distance_m + float(self.rng.normal(0.0, 0.01))
                if self.rng.random() < 0.05:
                    d += 0.8  # an outlier for the gate
                out.append(Rangefinder(r.t_s, r.sysid, d, True, r.source))
                if self.rng.random() < 0.2:  # now and then two readings in one tick
                    out.append(Rangefinder(r.t_s, r.sysid, d + 0.003, True, r.source))
            else:
                out.append(r)
        return out


def _ticks(st: Station, seconds: float) -> None:
    st.loop.run(max_ticks=round(seconds / st.config.period_s))


@pytest.fixture(scope="module")
def flight(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Arm, take off on the ramp, a short telemetry gap (held, then resumed), hand back to the
    sticks in the air, re-engage there, a long loss (LAND, silence, the link back), then kill:
    every path of the supervisor."""
    path = tmp_path_factory.mktemp("rerun") / "flight.mcap"
    clock = SimClock(1000.0)
    board = NoisyBoard(clock, np.random.default_rng(7))
    with Recorder(path, metadata={"command": "test"}) as rec:
        st = Station(board, clock=clock, recorder=rec, curve=board.curve)
        st.preflight(True, "test board")
        st.request_arm()
        _ticks(st, 1.2)
        st.alt_hold(True, 1.0, rate_mps=0.5)
        _ticks(st, 8.0)
        board.lost = True
        _ticks(st, 0.5)
        board.lost = False
        _ticks(st, 2.0)
        st.set_sticks(1500, 1500, 1500, 1560)
        st.alt_hold(False)
        _ticks(st, 0.5)
        st.alt_hold(True, 0.8)
        _ticks(st, 3.0)
        board.lost = True
        _ticks(st, 5.0)
        board.lost = False
        _ticks(st, 1.5)
        st.kill()
        _ticks(st, 0.3)
    return path


def _report(path: Path, gains: str | None = None) -> RerunReport:
    f = load_flight(open_recording(path))
    cfg = f.config if gains is None else apply_overrides(f.config, parse_gains(gains))
    return compare(f, rerun(f, cfg), changed_parameters(f.config, cfg))


def test_the_recording_says_what_each_tick_consumed(flight: Path) -> None:
    rec = open_recording(flight)
    ticks = [m for _t, _ns, m in rec.messages([topics.TICK])]
    assert len(ticks) == rec.counts[topics.ESTIMATE]
    assert sum(t["imu_n"] for t in ticks) == rec.counts[topics.IMU]
    assert sum(t["rangefinder_n"] for t in ticks) == rec.counts[topics.RANGEFINDER]
    states = {t["state"] for t in ticks}
    # no "silent" since #32: a lost link keeps LAND and heartbeats until heard disarmed
    assert {"arming", "manual", "takeoff", "hold", "link_lost", "killed"} <= states
    assert any(t["link_lost"] for t in ticks)
    assert sum(t["intent_n"] for t in ticks) == rec.counts[topics.INTENT]
    assert rec.counts[topics.SUPERVISOR] >= 8
    assert rec.counts[topics.SETUP] == 1


def test_unchanged_parameters_rerun_bit_identical(flight: Path) -> None:
    report = _report(flight)
    assert report.identical
    assert report.overrides == ()
    by_name = {s.signal: s for s in report.signals}
    assert by_name["/gcs/estimate.alt_m"].compared == report.ticks > 400
    assert by_name["/gcs/alt_controller.throttle_us"].compared > 300
    assert all(s.differing == 0 and s.max_abs in (0.0, None) for s in report.signals)
    assert report.only_recorded == report.only_rerun == 0


def test_a_changed_altitude_gain_moves_only_the_controller(flight: Path) -> None:
    g = StationConfig().altitude.gains
    report = _report(flight, f"alt.kp={g.kp + 3.0},alt.ki=3")
    assert not report.identical
    assert report.overrides == (f"altitude.gains.kp: {g.kp} -> {g.kp + 3.0}",
                                f"altitude.gains.ki: {g.ki} -> 3.0")
    by_name = {s.signal: s for s in report.signals}
    # open loop on the recorded sensor data: the estimator's own state cannot change, the
    # controller must; the hold's filter predicts on the commands, so it follows them
    hold_filter = (f"{topics.ESTIMATE}.control_alt_m", f"{topics.ESTIMATE}.control_vel_mps")
    assert all(s.identical for n, s in by_name.items()
               if n.startswith(topics.ESTIMATE) and n not in hold_filter)
    assert not all(by_name[n].identical for n in hold_filter)
    p = by_name["/gcs/alt_controller.p"]
    assert p.differing > 0 and p.max_abs is not None and p.max_abs > 0.0
    assert p.rms is not None and 0.0 < p.rms <= p.max_abs
    thr = by_name["/gcs/alt_controller.throttle_us"]
    assert thr.differing > 0 and thr.max_abs is not None and thr.max_abs >= 1.0


def test_a_changed_estimator_moves_the_estimate(flight: Path) -> None:
    report = _report(flight, "est.sonar_sigma_m=0.08")
    alt = {s.signal: s for s in report.signals}["/gcs/estimate.alt_m"]
    assert alt.differing > 0 and alt.max_abs is not None and 0.0 < alt.max_abs < 1.0
    other = _report(flight, "estimator_kind=complementary")
    assert other.overrides == ("estimator_kind: kalman -> complementary",)
    assert not other.identical


def test_cli_json_and_text(flight: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(flight), "--rerun", "--json"]) == 0
    same = json.loads(capsys.readouterr().out)
    assert same["bit_identical"] is True and same["overrides"] == []
    assert main(["replay", str(flight), "--rerun", "--json", "--gains", "alt.kd=2"]) == 0
    diff = json.loads(capsys.readouterr().out)
    assert diff["bit_identical"] is False
    d = {s["signal"]: s for s in diff["signals"]}["/gcs/alt_controller.d"]
    assert d["differing"] > 0 and d["max_abs"] > 0.0 and d["rms"] > 0.0
    assert main(["replay", str(flight), "--rerun"]) == 0
    assert "bit-identical" in capsys.readouterr().out
    assert main(["replay", str(flight), "--rerun", "--gains", "alt.kp=10"]) == 0
    out = capsys.readouterr().out
    assert "DIFFERS" in out and "/gcs/alt_controller.p" in out


def test_gains_from_a_toml_file(flight: Path, tmp_path: Path,
                                capsys: pytest.CaptureFixture[str]) -> None:
    toml = tmp_path / "tune.toml"
    kp = StationConfig().altitude.gains.kp
    toml.write_text(f"[altitude.gains]\nkp = {kp}\n")  # the recorded value: still identical
    assert main(["replay", str(flight), "--rerun", "--json", "--gains", str(toml)]) == 0
    assert json.loads(capsys.readouterr().out)["bit_identical"] is True
    toml.write_text("[altitude]\nmass_kg = 1.8\n")
    assert main(["replay", str(flight), "--rerun", "--json", "--gains", str(toml)]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["overrides"] == ["altitude.mass_kg: 1.63 -> 1.8"]
    assert not report["bit_identical"]


def test_parse_gains_nests_dotted_keys_and_reads_toml_values() -> None:
    table = parse_gains("alt.kp=1.2, est.gate_sigma=3,position.gains.kp=2,estimator_kind=kalman")
    assert table == {"altitude": {"gains": {"kp": 1.2}}, "estimator": {"gate_sigma": 3},
                     "position": {"gains": {"kp": 2}}, "estimator_kind": "kalman"}


def test_the_recorded_setup_keeps_non_finite_parameters(flight: Path) -> None:
    base = StationConfig()
    gains = dataclasses.replace(base.altitude.gains, setpoint_slew_per_s=math.inf)
    cfg = dataclasses.replace(base, altitude=dataclasses.replace(base.altitude, gains=gains))
    assert params_json.loads(StationConfig, params_json.dumps(cfg)) == cfg
    with pytest.raises(ValueError):
        params_json.loads(StationConfig, "[1, 2]")
    assert load_flight(open_recording(flight)).config.estimator_kind is EstimatorKind.KALMAN


@pytest.mark.parametrize(("gains", "needle"), [
    ("alt.kq=1", "kq: unknown key"),
    ("alt.kp", "expected key=value"),
    ("alt.kp=fast", "expected a number"),
    ("alt.kp=-1", "must be >= 0"),
    ("estimator_kind=magic", "expected one of"),
    ("missing.toml", "no such file"),
])
def test_bad_gains_end_in_one_line(flight: Path, gains: str, needle: str,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(flight), "--rerun", "--gains", gains]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and "\n" not in err


def test_gains_without_rerun_is_a_usage_error(flight: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(flight), "--gains", "alt.kp=1"]) == 2
    assert "--rerun" in capsys.readouterr().err


def test_recordings_that_cannot_be_rerun(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(tmp_path / "nope.mcap"), "--rerun"]) == 2
    not_mcap = tmp_path / "junk.mcap"
    not_mcap.write_bytes(b"not a recording at all")
    assert main(["replay", str(not_mcap), "--rerun"]) == 2
    old = tmp_path / "old.mcap"
    with Recorder(old, metadata={}) as rec:
        rec.put(topics.ESTIMATE, 1.0, {"alt_m": 0.0})
    assert main(["replay", str(old), "--rerun"]) == 2
    assert "/gcs/setup" in capsys.readouterr().err
    short = tmp_path / "short.mcap"
    st = Station(FakeBoard(SimClock()), clock=SimClock())
    with Recorder(short, metadata={}) as rec:
        setup = StationSetup(params_json.dumps(st.config), params_json.dumps(st.curve), 0.5,
                             params_json.dumps(st.supervisor_params))
        rec.put(topics.SETUP, 1.0, setup)
        rec.put(topics.TICK, 1.0, TickRecord(0, 1.0, 0.025, 3, 0, 0, 0, 0, 0, False, True,
                                             False, 0, 1.0, 0.0, st.snapshot().state, False))
        rec.put(topics.ESTIMATE, 1.0, {"alt_m": 0.0})
    with pytest.raises(UsageError, match="ran out of"):
        load_flight(open_recording(short))
    assert main(["replay", str(short), "--rerun"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tick 0 consumed 3 /vehicle/imu records" in err[0]
