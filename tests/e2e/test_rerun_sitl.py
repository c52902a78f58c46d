"""`quadgcs fly` on the bundled SITL, recorded, then `quadgcs replay --rerun` on the recording."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from gcs.cli import main
from gcs.config import StationConfig

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def sitl_flight(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("rerun") / "flight.mcap"
    proc = subprocess.run(
        [sys.executable, "-m", "gcs", "fly", "--hold", "5", "--speedup", "2", "--seed", "5",
         "-o", str(out)],
        cwd=REPO, capture_output=True, text=True, timeout=240,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return out


def _rerun(path: Path, capsys: pytest.CaptureFixture[str], *gains: str) -> dict:
    argv = ["replay", str(path), "--rerun", "--json"]
    for g in gains:
        argv += ["--gains", g]
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_sitl_flight_reruns_bit_identical(sitl_flight: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    report = _rerun(sitl_flight, capsys)
    assert report["bit_identical"] is True
    assert report["ticks"] > 200
    signals = {s["signal"]: s for s in report["signals"]}
    assert signals["/gcs/estimate.alt_m"]["compared"] == report["ticks"]
    assert signals["/gcs/alt_controller.throttle_us"]["compared"] > 100  # it flew on the PC loop
    assert all(s["differing"] == 0 for s in report["signals"])


def test_sitl_flight_rerun_with_other_gains_differs(sitl_flight: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    report = _rerun(sitl_flight, capsys, "alt.kp=13.5,alt.kd=3")
    assert report["bit_identical"] is False
    gains = StationConfig().altitude.gains
    assert report["overrides"] == [f"altitude.gains.kp: {gains.kp} -> 13.5",
                                   f"altitude.gains.kd: {gains.kd} -> 3.0"]
    signals = {s["signal"]: s for s in report["signals"]}
    assert signals["/gcs/estimate.alt_m"]["differing"] == 0  # same sensor data, same estimate
    thr = signals["/gcs/alt_controller.throttle_us"]
    assert thr["differing"] > 0 and thr["max_abs"] >= 1 and 0 < thr["rms"] <= thr["max_abs"]
