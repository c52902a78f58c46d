"""Position legs in lockstep: how the horizontal hold moves the vehicle from one spot to the next.

A leg is what a mission asks for between two samples or waypoints: the set point jumps `leg_m`
north, and the vehicle has to get there and stay. Flown on the bundled SITL in lockstep (the
station's own code on simulated time), scored on motion capture: overshoot past the new spot
and the time until the vehicle stays within `band_m` of it. `bench/position_legs.py` prints
these; a test holds the position loop to the mission issue's floors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gcs.config import StationConfig
from gcs.control.attitude import yaw_from_quat
from gcs.control.position_controller import PositionSetpoint
from gcs.flight import FlightPlan, FlightRunner
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions
from gcs.station.station import StationSnapshot
from gcs.supervisor import SupervisorState


@dataclass(frozen=True, slots=True)
class LegResult:
    """One leg, scored on motion capture (north axis; the set point moved north)."""

    leg_m: float
    overshoot_pct: float  # furthest past the new spot, in % of the leg
    settle_s: float  # from the set point's jump until the vehicle stays within the band
    band_m: float
    max_cross_m: float  # furthest off the line of the leg (east)
    alt_dev_m: float  # largest altitude excursion from the hold during the leg


def _score(samples: list[tuple[float, float, float, float]], t0: float, start_n: float,
           target_n: float, east0: float, alt0: float, band_m: float) -> LegResult:
    leg = target_n - start_n
    sign = 1.0 if leg >= 0 else -1.0
    past = max(((n - target_n) * sign for _t, n, _e, _a in samples), default=0.0)
    settle = math.inf
    for i, (t, _n, _e, _a) in enumerate(samples):
        if all(abs(n - target_n) <= band_m for _t2, n, _e2, _a2 in samples[i:]):
            settle = t - t0
            break
    return LegResult(
        leg_m=abs(leg),
        overshoot_pct=100.0 * max(past, 0.0) / abs(leg),
        settle_s=settle,
        band_m=band_m,
        max_cross_m=max((abs(e - east0) for _t, _n, e, _a in samples), default=0.0),
        alt_dev_m=max((abs(a - alt0) for _t, _n, _e, a in samples), default=0.0),
    )


def fly_legs(profile: str, legs_m: tuple[float, ...], *, seed: int = 1,
             observe_s: float = 8.0, band_m: float = 0.05, alt_m: float = 1.0,
             config: StationConfig | None = None) -> list[LegResult]:
    """Take off to `alt_m`, then fly each leg, north from the start's south side and south from
    its north side, and score it."""
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                             fix_failsafe=True)
    results: list[LegResult] = []
    lockstep = LockstepSession(options, config=config)
    with lockstep as session:
        st = session.first.station
        runner = FlightRunner(st, FlightPlan(alt_m=alt_m, hold_s=1.0), None, idle=lockstep.tick)
        samples: list[tuple[float, float, float, float]] = []

        def sample(snap: StationSnapshot) -> None:
            if snap.mocap is not None:
                n, e, d = snap.mocap.pos_n
                samples.append((snap.t_s, n, e, -d))

        st.add_listener(sample)
        runner.arm()
        st.alt_hold(True, alt_m, rate_mps=0.5)
        runner.wait("take-off", lambda s: s.state is not SupervisorState.MANUAL, 2.0)
        pose = st.snapshot(loop_stats=False).mocap
        assert pose is not None, "the bundled SITL's default world has motion capture"
        n0, e0, _ = pose.pos_n
        yaw0 = yaw_from_quat(pose.q_nb)
        st.set_position_setpoint(PositionSetpoint(n0, e0, yaw0))
        runner.wait("the hold altitude", lambda s: s.state is SupervisorState.HOLD
                    and s.estimate is not None and abs(s.estimate.alt_m - alt_m) < 0.05,
                    alt_m / 0.5 + 20.0)
        runner.pause(4.0)
        here = n0
        for leg in legs_m:
            # each leg heads back across the start, so the legs stay inside the room (a 6 m
            # room's wall stops a vehicle 2.75 m from its centre)
            target = here + (leg if here <= n0 else -leg)
            samples.clear()
            t0 = st.clock.now_s()
            st.set_position_setpoint(PositionSetpoint(target, e0, yaw0))
            runner.pause(observe_s)
            results.append(_score(list(samples), t0, here, target, e0, alt_m, band_m))
            here = target
        runner.land()
    return results
