"""Shared fixtures for the recording tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from logs import Recorder
from tests.fixture_paths import FLIGHT_TLOG
from tests.logs.check_flights import clean_flight

__all__ = ["clean_flight"]  # a session fixture: one recorded lockstep hold for `logs check`
from tests.logs.flightgen import record, synthetic_flight

ANCHOR_NS = 1_795_000_000_000_000_000


@pytest.fixture
def flight_tlog() -> Path:
    """The real ArduCopter 4.7 SITL flight log."""
    if not FLIGHT_TLOG.exists():
        pytest.skip(f"the real 4.7 flight log {FLIGHT_TLOG} is not here "
                    "(it comes with ../shared/fixtures)")
    return FLIGHT_TLOG


@pytest.fixture
def recorded_flight(tmp_path: Path) -> tuple[Path, dict[str, int]]:
    """A 6 s synthetic flight recorded to MCAP, and how many messages went to each topic."""
    rng = np.random.default_rng(7)
    with Recorder(
        tmp_path / "flight.mcap",
        metadata={"connection": "tcp:127.0.0.1:5760", "params": {"MOT_THST_HOVER": 0.39}},
        anchor_ns=ANCHOR_NS,
    ) as rec:
        counts = record(rec, synthetic_flight(6.0, rng))
        rec.event(101.0, "info", "armed")
    counts["/log"] = 1
    counts["/tf"] = 1
    return rec.path, counts
