"""Take-off on the SITL: it waits for the motors and does not overshoot.

Judged from the flight's own recording: the supervisor's transitions, the altitude controller's
terms and the SITL's truth. Every case flies in lockstep (the station's own code and MAVLink
bytes on simulated time: the same flight whatever the machine is doing), and one flies over TCP
at 4x as well, where the sped-up wall clock adds its own timing noise."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gcs import topics
from gcs.cli import build_parser
from gcs.commands.fly import fly
from gcs.config import StationConfig
from gcs.scoring import takeoff_peak_m
from logs import open_recording

EST = StationConfig().estimator


def _fly(tmp_path: Path, how: str, *argv: str) -> tuple[dict[str, Any], Path]:
    out = tmp_path / "flight.mcap"
    clock = ["--lockstep"] if how == "lockstep" else ["--speedup", "4"]
    args = build_parser().parse_args(["fly", "--seed", "5", "--fix-failsafe", *clock,
                                      "-o", str(out), *argv])
    return fly(args), out


def _read(path: Path) -> dict[str, list[tuple[float, Any]]]:
    rec = open_recording(path)
    want = [topics.SUPERVISOR, topics.ALT_CONTROLLER, topics.SIM_TRUTH, topics.ESTIMATE]
    out: dict[str, list[tuple[float, Any]]] = {t: [] for t in want}
    for topic, ns, msg in rec.messages(want):
        out[topic].append((ns / 1e9, msg))
    return out


@pytest.mark.e2e
@pytest.mark.timeout(240)
@pytest.mark.parametrize(("how", "profile", "alt_m"), [
    # with the real 3.2.1 analog sonar (nothing used below 20 cm, 6 cm steps): the lift-off
    # felt by the accelerometer, the band crossed on it (this seed overshot 16.0 % to 1 m and
    # 7.1 % to 2 m while the take-off waited for the sonar; the real 3.2.1 14.5-22.8 / 8.1 %)
    ("lockstep", "apm25", 1.0),
    ("lockstep", "apm25", 2.0),
    ("lockstep", "copter4", 1.0),
    ("lockstep", "copter4", 2.0), ("tcp", "copter4", 2.0)])
def test_takeoff_waits_for_the_motors_and_overshoots_at_most_5_percent(
        tmp_path: Path, how: str, profile: str, alt_m: float) -> None:
    summary, path = _fly(tmp_path, how, "--profile", profile, "--alt", str(alt_m),
                         "--hold", "2")
    assert summary["status"] == "ok"
    rec = _read(path)
    moves = {(m["previous"], m["state"]): t for t, m in rec[topics.SUPERVISOR]}
    armed_t = moves[("arming", "manual")]
    ramp_t = moves[("spool_up", "takeoff")]
    hold_t = moves[("takeoff", "hold")]
    land_t = moves[("hold", "vehicle")]
    if profile == "copter4":  # the firmware holds the motors ~2 s after arming
        assert ramp_t - armed_t >= 2.0
    # no PID, so no integrator, before the vehicle was felt to leave the floor
    assert all(t >= hold_t for t, _ in rec[topics.ALT_CONTROLLER])
    # and it starts from the throttle that lifted the vehicle, not a wound-up one (the fault
    # this replaces reached 1735 us on the floor): the trim of a throttle near hover, never
    # near i_max (3 m/s²); under the assumed hover when the vehicle was felt to lift below it
    # (-0.50 m/s² once at 4x over TCP)
    first = rec[topics.ALT_CONTROLLER][0][1]
    assert -1.5 < first["i"] < 1.5 and first["throttle_us"] < 1650
    truth = np.array([(t, -m["pos_n"]["z"]) for t, m in rec[topics.SIM_TRUTH]])
    peak = takeoff_peak_m(truth[:, 0], truth[:, 1], armed_t, hold_t, land_t, EST.rest_alt_m)
    overshoot_pct = (peak - alt_m) / alt_m * 100.0
    assert overshoot_pct <= 5.0, f"peak {peak:.3f} m for {alt_m} m"
    assert peak >= alt_m - 0.1  # it did get there
