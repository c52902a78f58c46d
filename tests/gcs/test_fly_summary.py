"""`quadgcs fly`'s summary: the score's source, bias and spread, in JSON and in words."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

from firmware_link import FirmwareInfo
from firmware_link.protocol import WireVersion
from firmware_link.records import Dialect
from gcs.commands.fly import _print_summary, _summary_dict
from gcs.estimation import EstimatorCounts
from gcs.flight import FlightSummary

BASE = FlightSummary(
    rms_error_m=0.0125, max_error_m=0.04, error_source="truth", mean_error_m=-0.0075,
    std_error_m=0.01, truth_coverage=0.5, truth_rate_hz=50.0, step=None, jitter_p50_ms=0.01,
    jitter_p99_ms=0.1, compute_p99_ms=1.0, overruns=0, ticks=100, rx_messages=1000,
    lost_messages=0, corrupted=0, hover_throttle=0.53, samples=())
FW = FirmwareInfo(dialect=Dialect.APM25, version="ArduCopter V3.2.1",
                  gcs_sysid_param="SYSID_MYGCS", wire=WireVersion.V1, evidence=(),
                  source="STATUSTEXT banner")


def test_json_carries_bias_spread_source_and_coverage() -> None:
    d = _summary_dict(BASE, None, FW)
    assert (d["mean_error_m"], d["std_error_m"], d["error_source"]) == (-0.0075, 0.01, "truth")
    assert (d["truth_coverage"], d["truth_rate_hz"]) == (0.5, 50.0)
    json.loads(json.dumps(d, allow_nan=False))


def test_nothing_scored_is_null_not_nan() -> None:
    s = dataclasses.replace(BASE, error_source="none", rms_error_m=math.nan,
                            max_error_m=math.nan, mean_error_m=math.nan, std_error_m=math.nan,
                            truth_coverage=0.0, truth_rate_hz=0.0)
    d = _summary_dict(s, None, FW)
    assert d["rms_error_m"] is None and d["mean_error_m"] is None
    json.loads(json.dumps(d, allow_nan=False))


@pytest.mark.parametrize(("source", "needle"), [
    ("truth", "vs truth (50 % of the hold, 50 Hz): RMS 1.25 cm = bias -0.75 cm, std 1.00 cm"),
    ("estimate", "vs the station's own estimate (no truth"),
])
def test_text_names_the_source(source: str, needle: str, capsys: pytest.CaptureFixture[str]
                               ) -> None:
    _print_summary(_summary_dict(dataclasses.replace(BASE, error_source=source), None,
                                 FW))
    assert needle in capsys.readouterr().out


def test_text_for_an_unscored_hold(capsys: pytest.CaptureFixture[str]) -> None:
    s = dataclasses.replace(BASE, error_source="none", rms_error_m=math.nan)
    _print_summary(_summary_dict(s, None, FW))
    assert "not scored" in capsys.readouterr().out


def test_what_the_estimator_set_aside_is_reported(capsys: pytest.CaptureFixture[str]) -> None:
    s = dataclasses.replace(BASE, estimator=EstimatorCounts(7, 2, 3, 1))
    d = _summary_dict(s, None, FW)
    assert d["estimator"] == {"sonar_rejected": 7, "late_bursts": 2, "imu_repeats": 3,
                              "implausible_times": 1}
    _print_summary(d)
    out = capsys.readouterr().out
    assert "7 sonar readings (gate), 3 IMU samples received twice, 1 stamped ahead" in out


def test_the_firmware_is_named_with_how_it_was_identified(
        capsys: pytest.CaptureFixture[str]) -> None:
    d = _summary_dict(BASE, None, FW)
    assert (d["firmware"], d["firmware_source"], d["dialect"]) == (
        "ArduCopter V3.2.1", "STATUSTEXT banner", "apm25")
    _print_summary(d)
    assert "firmware ArduCopter V3.2.1 (identified by STATUSTEXT banner)" in (
        capsys.readouterr().out)
