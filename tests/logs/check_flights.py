"""Recorded lockstep flights for the `logs check` tests: clean, and with one fault made."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from gcs.errors import FlightFailed

HOLD_S = 5.0


def fly_recorded(out: Path, *, seed: int = 1, profile: str = "apm25", hold_s: float = 10.0,
                 world: dict[str, Any] | None = None, faults: dict[str, Any] | None = None,
                 config: Path | None = None,
                 during: Callable[[Any], None] | None = None) -> tuple[Path, dict[str, Any]]:
    """Fly a lockstep hold recorded to `out`; its summary (or the failure) beside the file.

    `during(session)` runs once the session is open, before the flight (to add a listener)."""
    from gcs.commands.fly import fly_session
    from gcs.config import load_config
    from gcs.flight import FlightPlan
    from gcs.lockstep_session import LockstepSession
    from gcs.station.session import SessionOptions
    from lab.campaign.tables import world_table
    from lab.lockstep import install

    install()
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=True,
                             output=out, fix_failsafe=True)
    summary: dict[str, Any]
    with LockstepSession(options, world=world_table(None, world or {}),
                         config=load_config(config), faults=faults) as session:
        if during is not None:
            during(session)
        try:
            summary = fly_session(session, FlightPlan(alt_m=1.0, hold_s=hold_s),
                                  pilot_signals=False)
        except FlightFailed as exc:
            summary = {"status": "failed", "reason": str(exc)}
    return out, summary


def starve(every: int = 5, extra_s: float = 0.04) -> Callable[[Any], None]:
    """A `during` that makes every `every`-th tick of the first station take `extra_s` longer
    than its period allows (the simulation runs on while the tick computes): a starved loop."""

    def install(session: Any) -> None:
        station = session.first.station
        count = [0]

        def slow(_snapshot: Any) -> None:
            count[0] += 1
            if count[0] % every == 0:
                session.clock.sleep_until(session.clock.now_s() + extra_s)

        station.add_listener(slow)

    return install


@pytest.fixture(scope="session")
def clean_flight(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A clean 5 s lockstep hold, recorded (flown once for every test that reads it)."""
    path, summary = fly_recorded(tmp_path_factory.mktemp("clean") / "fly.mcap", hold_s=HOLD_S)
    assert summary["status"] == "ok", summary
    return path
