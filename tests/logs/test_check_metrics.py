"""Each check's metric on a made-up flight: the fault in, the check fails; out, it passes."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from logs.check import FlightSeries, FrameInfo, Status, evaluate, load_thresholds, measure
from logs.check.thresholds import ThresholdError

PERIOD_S = 0.025


def flight(seconds: float = 30.0, *, states: bool = True) -> FlightSeries:
    """A quiet flight: armed and in the air from 2 s, a hold at 1 m from 6 s."""
    fs = FlightSeries()
    fs.message("/gcs/setup", 0.0, {"config_json": '{"period_s": 0.025, "altitude": {"gains": '
                                   '{"i_max": 3.0}, "throttle_min_us": 1000, '
                                   '"throttle_max_us": 2000}, "flight": {"settle_s": 1.0}}'})
    if states:
        for t, state in ((1.0, "spool_up"), (2.0, "takeoff"), (6.0, "hold")):
            fs.message("/gcs/supervisor", t, {"state": state, "reason": ""})
    for k in range(int(seconds)):
        fs.message("/vehicle/heartbeat", float(k), {"mode": 0, "armed": k >= 1})
    return fs


def judged(fs: FlightSeries) -> dict[str, tuple[Status, float]]:
    return {r.key: (r.status, r.value) for r in evaluate(measure(fs), load_thresholds(None))}


def _ticks(seconds: float = 30.0) -> np.ndarray:
    return np.arange(0.0, seconds, PERIOD_S)


@pytest.mark.parametrize(("late_ms", "expected"), [(0.0, Status.PASS), (20.0, Status.FAIL)])
def test_late_ticks(late_ms: float, expected: Status) -> None:
    fs = flight()
    for k, t in enumerate(_ticks()):
        late = late_ms if k % 20 == 0 else 0.0
        fs.message("/gcs/loop", t, {"jitter_ms": 0.1, "lateness_ms": late, "compute_ms": 1.0,
                                    "overrun": False})
    assert judged(fs)["loop.late_ticks_pct"][0] is expected


def _rx(fs: FlightSeries, times: np.ndarray, kind: str = "RAW_IMU", drop: int = 0) -> None:
    seq = 0
    for i, t in enumerate(times):
        if drop and i % drop == 0:
            seq = (seq + 1) % 256  # a frame lost: its sequence number never arrives
        fs.frame(FrameInfo(float(t), "rx", 1, 1, seq, kind))
        seq = (seq + 1) % 256


def test_link_gaps_and_silence_and_loss() -> None:
    fs = flight()
    fs.frame(FrameInfo(0.5, "tx", 255, 190, 0, "REQUEST_DATA_STREAM",
                       {"req_stream_id": 1, "req_message_rate": 40, "start_stop": 1}))
    t = np.arange(0.0, 30.0, 0.025)
    t = t[(t < 10.0) | (t > 12.0)]  # a 2 s silence
    _rx(fs, t, drop=4)
    j = judged(fs)
    assert j["link.gaps"][0] is Status.WARN and j["link.gaps"][1] == 1
    assert j["link.longest_silence_s"][0] is Status.FAIL
    assert math.isclose(j["link.longest_silence_s"][1], 2.05, abs_tol=0.03)
    assert j["link.loss_pct"][0] is Status.FAIL and 19 < j["link.loss_pct"][1] < 21
    assert j["link.stream_rate_pct"][0] is Status.PASS  # 40 Hz asked, 40 Hz less the silence


def test_a_stream_slower_than_asked_fails() -> None:
    fs = flight()
    fs.frame(FrameInfo(0.5, "tx", 255, 190, 0, "REQUEST_DATA_STREAM",
                       {"req_stream_id": 1, "req_message_rate": 40, "start_stop": 1}))
    _rx(fs, np.arange(0.0, 30.0, 0.1))  # 10 Hz of the 40 asked
    status, value = judged(fs)["link.stream_rate_pct"]
    assert status is Status.FAIL and value == pytest.approx(25.0, abs=1.0)


def _estimates(fs: FlightSeries, innovation_m: float, rejected_every: int) -> None:
    rejected = 0
    for k, t in enumerate(_ticks()):
        used = k % 2 == 0
        if rejected_every and k % rejected_every == 1:
            rejected += 1
        fs.message("/gcs/estimate", t, {"alt_m": 1.0 if t > 4 else 0.06,
                                        "innovation_m": innovation_m * (-1) ** (k // 2),
                                        "rejected_total": rejected, "sonar_used": used})
        fs.message("/vehicle/sim_truth", t, {"pos_n": {"z": -(1.0 if t > 4 else 0.06)}})


def test_innovations_and_rejections() -> None:
    fs = flight()
    _estimates(fs, 0.01, 0)
    j = judged(fs)
    assert j["estimator.innovation_rms_m"][0] is Status.PASS
    assert j["estimator.rejected_pct"] == (Status.PASS, 0.0)
    assert j["estimator.vs_reference_rms_m"][0] is Status.PASS
    fs = flight()
    _estimates(fs, 0.2, 3)
    j = judged(fs)
    assert j["estimator.innovation_rms_m"][0] is Status.FAIL
    assert j["estimator.rejected_pct"][0] is Status.FAIL


def _control(fs: FlightSeries, *, i: float = 0.5, hover: tuple[float, float] = (0.5, 0.5),
             throttle_us: float = 1500.0, error_m: float = 0.0) -> None:
    ticks = _ticks()
    for k, t in enumerate(ticks):
        h = hover[0] + (hover[1] - hover[0]) * k / len(ticks)
        fs.message("/gcs/alt_controller", t, {"setpoint_m": 1.0, "error_m": 0.0, "i": i,
                                              "saturated": False, "throttle_us": throttle_us,
                                              "hover_throttle": h})
        fs.message("/gcs/estimate", t, {"alt_m": 1.0 + error_m * math.sin(t), "sonar_used": False,
                                        "innovation_m": 0.0, "rejected_total": 0})


def test_integrator_at_its_limit_and_hover_drift() -> None:
    fs = flight()
    _control(fs)
    j = judged(fs)
    assert j["control.integrator_limit_pct"] == (Status.PASS, 0.0)
    assert j["control.hover_drift_pct"][0] is Status.PASS
    assert j["control.stick_limit_pct"] == (Status.PASS, 0.0)
    fs = flight()
    _control(fs, i=-2.99, hover=(0.40, 0.70), throttle_us=2000.0)
    j = judged(fs)
    assert j["control.integrator_limit_pct"][0] is Status.FAIL
    assert j["control.hover_drift_pct"][0] is Status.FAIL
    assert j["control.stick_limit_pct"] == (Status.FAIL, 100.0)


def test_the_hold_is_scored_on_the_estimate_without_truth_and_says_so() -> None:
    fs = flight()
    _control(fs, error_m=0.3)
    j = judged(fs)
    assert j["hold.std_m"][0] is Status.FAIL and j["hold.bias_m"][0] is Status.PASS
    results = {r.key: r for r in evaluate(measure(fs), load_thresholds(None))}
    assert results["hold.rms_m"].source == "estimate"


def _battery(fs: FlightSeries, ohm: float, full_v: float = 12.4) -> None:
    for k, t in enumerate(np.arange(0.0, 30.0, 0.5)):
        amp = 5.0 + 15.0 * (k % 4) / 3
        fs.message("/vehicle/battery", t, {"voltage_v": full_v - 0.01 * t - ohm * amp,
                                           "current_a": amp})


def test_battery_sag_per_amp_and_the_lowest_cell() -> None:
    fs = flight()
    _battery(fs, 0.03)
    j = judged(fs)
    status, value = j["power.sag_v_per_a"]
    assert status is Status.PASS and value == pytest.approx(0.03, abs=0.002)
    assert j["power.min_cell_v"][0] is Status.PASS
    fs = flight()
    _battery(fs, 0.15, full_v=12.0)
    j = judged(fs)
    status, value = j["power.sag_v_per_a"]
    assert status is Status.FAIL and value == pytest.approx(0.15, abs=0.002)
    assert j["power.min_cell_v"][0] is Status.FAIL  # (12.0 - 0.3 - 3.0) / 3 < 3.3 V


def test_modes_nobody_asked_for_and_refusals() -> None:
    fs = flight()
    fs.frame(FrameInfo(4.0, "tx", 255, 190, 0, "SET_MODE", {"custom_mode": 2}))
    for k, mode in ((5, 2), (8, 5), (10, 2), (12, 16), (14, 2), (16, 9)):
        fs.message("/vehicle/heartbeat", k + 0.5, {"mode": mode, "armed": True})
    fs.message("/vehicle/command_ack", 3.0, {"command": 400, "result": 4})
    fs.message("/vehicle/command_ack", 3.5, {"command": 400, "result": 0})
    fs.message("/vehicle/command_ack", 9.0, {"command": 176, "result": 3})
    j = judged(fs)
    assert j["events.unasked_modes"][1] >= 2  # LOITER, POSHOLD (ALT_HOLD was asked at 4 s)
    assert j["events.failsafes"] == (Status.FAIL, 1.0)  # the LAND nobody asked for
    assert j["events.refusals"] == (Status.WARN, 1.0)  # arming retried and accepted


def test_nothing_measurable_is_skip_never_pass() -> None:
    fs = FlightSeries()
    assert {s for s, _v in judged(fs).values()} == {Status.SKIP}


def test_a_thresholds_file_overrides_and_a_bad_one_says_what_is_wrong(tmp_path: Path) -> None:
    good = tmp_path / "t.toml"
    good.write_text('["link.loss_pct"]\nwarn = 0.5\nfail = 1.0\n', encoding="utf-8")
    assert load_thresholds(good)["link.loss_pct"].fail == 1.0
    for text, words in (
        ('["link.nope"]\nwarn = 1\n', "unknown check 'link.nope'"),
        ('["link.loss_pct"]\nwarm = 1\n', "unknown key 'warm'"),
        ('["link.loss_pct"]\nwarn = "x"\n', "expected a finite number"),
        ('["link.loss_pct"]\nwarn = 5\nfail = 1\n', "must be at or above warn"),
        ("[[[", "not valid TOML"),
    ):
        bad = tmp_path / "bad.toml"
        bad.write_text(text, encoding="utf-8")
        with pytest.raises(ThresholdError) as err:
            load_thresholds(bad)
        assert str(bad) in str(err.value) and words in str(err.value)
        assert "\n" not in str(err.value)
