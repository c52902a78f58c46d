"""The pilot's first minute (#34): `h` pressed on the floor takes off to the take-off altitude
(1.0 m), not to the 0.10 m the vehicle was at when it left the floor.

Textual's Pilot presses the keys of the live teleop app over a real station on the bundled
SITL in lockstep (the station's own code and MAVLink bytes on simulated time, the real 20 cm
rangefinder minimum), so the flight is the same whatever the machine is doing: the test steps
the station's ticks itself between key presses. The height is the simulation's truth, read
only to judge.
"""

from __future__ import annotations

from typing import Any

import pytest

from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from gcs.supervisor import SupervisorState
from gcs.tui.app import make_app
from gcs.tui.station_backend import StationBackend

SEED = 5
TAKEOFF_M = 1.0


def _truth_m(session: Any) -> float:
    """The centre of gravity's true height on the station's scale (0.06 m standing)."""
    return float(-session.sitl.sitl.sim.vehicle(1).vehicle.truth.pos_n[2])


def _ticks(session: Any, seconds: float, heights: list[float]) -> None:
    st = session.first.station
    for _ in range(round(seconds / 0.025)):
        st.run_tick()
        heights.append(_truth_m(session))


@pytest.mark.parametrize("profile", ["apm25", "copter4"])
async def test_h_from_the_floor_climbs_to_the_take_off_altitude(profile: str) -> None:
    options = SessionOptions(command="teleop", profile=profile, seed=SEED, record=False,
                             fix_failsafe=True)
    with LockstepSession(options) as session:
        st = session.first.station
        assert session.preflight[1].ok, session.preflight[1].summary()
        backend = StationBackend(st, url="lockstep", dialect=profile)
        app = make_app(backend)
        heights: list[float] = []
        async with app.run_test(size=(100, 30)) as pilot:
            await pilot.press("a")
            _ticks(session, 3.0, heights)
            assert st.snapshot().state is SupervisorState.MANUAL
            await pilot.press("h")
            _ticks(session, 20.0, heights)
            snap = st.snapshot()
            assert snap.state is SupervisorState.HOLD
            assert snap.alt_setpoint_m == pytest.approx(TAKEOFF_M)
            peak = max(heights)
            settled = heights[-round(2.0 / 0.025):]  # the last 2 s
            assert abs(sum(settled) / len(settled) - TAKEOFF_M) <= 0.05
            assert peak <= TAKEOFF_M * 1.05, f"overshoot {(peak / TAKEOFF_M - 1) * 100:.1f} %"
            app.redraw()
            await pilot.pause()
            assert "hold ON" in str(app.query_one("#altitude").render())
            await pilot.press("space")  # the pilot's kill
            _ticks(session, 3.0, heights)
            assert st.snapshot().state is SupervisorState.DISARMED
