"""`logs check` on recorded lockstep flights: a clean hold passes, and each fault a flight is
made to suffer fails the check that watches for it (and only the flights that suffered it)."""

from __future__ import annotations

from pathlib import Path

from gcs.flight_check import gather_file
from logs.check import CheckResult, Status, evaluate, load_thresholds, measure
from tests.logs.check_flights import HOLD_S, fly_recorded, starve


def check(path: Path) -> dict[str, CheckResult]:
    results = evaluate(measure(gather_file(path)), load_thresholds(None))
    return {r.key: r for r in results}


def test_a_clean_lockstep_hold_fails_nothing_and_measures_every_group(clean_flight: Path) -> None:
    results = check(clean_flight)
    bad = {k: (r.status, r.value, r.detail) for k, r in results.items()
           if r.status in (Status.FAIL, Status.WARN)}
    assert not bad
    groups = {r.threshold.group for r in results.values() if r.status is Status.PASS}
    assert groups == {"link", "loop", "estimator", "vibration", "control", "power", "events",
                      "hold"}
    assert results["hold.rms_m"].source == "truth"
    assert results["estimator.vs_reference_rms_m"].source == "truth"


def _fails(path: Path) -> set[str]:
    return {k for k, r in check(path).items() if r.status is Status.FAIL}


def test_a_lossy_link_fails_the_link_loss(tmp_path: Path) -> None:
    path, _ = fly_recorded(tmp_path / "lossy.mcap", hold_s=HOLD_S,
                           faults={"loss": 0.3, "loss_start_s": 15.0})
    results = check(path)
    assert results["link.loss_pct"].status is Status.FAIL
    assert 15.0 < results["link.loss_pct"].value < 35.0  # a share of the whole recording


def test_a_starved_loop_fails_the_loop_timing(tmp_path: Path) -> None:
    path, _ = fly_recorded(tmp_path / "starved.mcap", hold_s=HOLD_S, during=starve(every=5))
    fails = _fails(path)
    assert {"loop.overruns_pct", "loop.jitter_p99_ms"} <= fails
    assert not any(k.startswith("link.") or k.startswith("vibration.") for k in fails)


def test_a_vibrating_imu_fails_the_vibration_checks(tmp_path: Path) -> None:
    path, _ = fly_recorded(tmp_path / "vibe.mcap", hold_s=HOLD_S,
                           world={"sensors": {"imu": {"acc_vibration_mps2_full": 6.0}}})
    fails = _fails(path)
    assert {"vibration.acc_rms_x_mps2", "vibration.acc_rms_y_mps2",
            "vibration.acc_rms_z_mps2"} <= fails
    assert not any(k.startswith("link.") or k.startswith("loop.") for k in fails)


def test_the_vehicles_own_failsafe_land_fails_the_events(tmp_path: Path) -> None:
    """The uplink fades in the hold: the vehicle hears no ground station and lands by itself,
    a LAND nobody asked for."""
    path, summary = fly_recorded(tmp_path / "fade.mcap", hold_s=10.0,
                                 faults={"fade": "up", "fade_start_s": 22.0, "fade_s": 30.0})
    assert summary["status"] == "failed"
    results = check(path)
    assert results["events.failsafes"].status is Status.FAIL
    assert "LAND" in results["events.failsafes"].detail


def test_the_stations_link_loss_landing_fails_the_events(tmp_path: Path) -> None:
    path, _ = fly_recorded(tmp_path / "lost.mcap", hold_s=10.0,
                           faults={"fade": "both", "fade_start_s": 22.0, "fade_s": 8.0})
    results = check(path)
    assert results["events.failsafes"].status is Status.FAIL
    assert "link_lost" in results["events.failsafes"].detail
    assert results["link.longest_silence_s"].status is Status.FAIL


def test_a_hold_straining_at_the_stick_limit_fails_the_control_check(tmp_path: Path) -> None:
    """A 2.3 kg vehicle hovers a few µs under the station's throttle cap of 1740 µs: each
    correction upward meets the cap (a 2.2 kg one capped just over its 1707 µs hover met it on
    only 3-6 % of the ticks once its take-off and hold on the 3.2.1 sonar steps were smooth)."""
    config = tmp_path / "cap.toml"
    config.write_text("[altitude]\nthrottle_max_us = 1740\n", encoding="utf-8")
    path, _ = fly_recorded(tmp_path / "strain.mcap", hold_s=HOLD_S, config=config,
                           world={"vehicle": {"mass_kg": 2.3}})
    results = check(path)
    assert results["control.stick_limit_pct"].status is Status.FAIL
    assert "1740" in results["control.stick_limit_pct"].detail
