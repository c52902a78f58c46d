"""A scripted flight under the PC controller: arm, take off, hold, optional step, land, disarm.

This is the thesis's Chapter 7 experiment as a procedure: it drives a running `Station` through
intents, records one sample per tick through a station listener, and scores the hold (RMS, bias,
spread and worst altitude error) and the step (overshoot, settling time) with `gcs.scoring`:
against the SITL's ground truth where the vehicle sends it, saying how much of the hold it
covered; against the station's own estimate only when there is no truth at all, and saying so.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from firmware_link.records import FlightMode
from gcs.config import HoldMode
from gcs.control.attitude import yaw_from_quat
from gcs.control.position_controller import PositionSetpoint
from gcs.errors import FlightFailed
from gcs.flight_plan import PHASE_STATES, FlightPlan, FlightSample, FlightSummary, Phase
from gcs.landing import descend, hand_over, may_descend
from gcs.launch import Launch, LaunchRules, LaunchStage, vehicle_said
from gcs.scoring import (
    ESTIMATE,
    TRUTH,
    Series,
    StepMetrics,
    distinct_reports,
    score_hold,
    step_response,
)
from gcs.scoring import truth_origin_m as _truth_origin
from gcs.station.station import Station, StationSnapshot
from gcs.supervisor import SupervisorState

__all__ = ["PHASE_STATES", "FlightPlan", "FlightRunner", "FlightSample", "FlightSummary", "Phase"]

POLL_S = 0.1
"""How often the flight script looks at the station. Rarely: every look takes the GIL, and a
look preempted by the OS while holding it would delay the real-time loop thread."""


def _truth_alt(snap: StationSnapshot) -> float | None:
    return -snap.truth.pos_n[2] if snap.truth is not None else None


class _FlyPort:
    """How the launch and the landing look and wait in a flight: every look checks the flight's
    phase; the runner's idle (a sleep, or in lockstep one tick) between looks."""

    def __init__(self, runner: FlightRunner) -> None:
        self.runner = runner
        self._last: StationSnapshot | None = None

    def now_s(self) -> float:
        return self.runner.station.clock.now_s()

    def look(self, vehicle: int) -> StationSnapshot:
        r = self.runner
        snap = self._last = r.station.snapshot(loop_stats=False)
        r.check(snap)
        return snap

    def idle(self) -> None:
        r = self.runner
        if r.on_progress is not None and self._last is not None:
            r.on_progress(self._last, r.phase)
        r.idle()

    def rest(self, seconds: float) -> None:
        self.runner.pause(seconds)

    def told(self, stage: LaunchStage, detail: str) -> None:
        pass  # a flight's progress lines come from its phases


class FlightRunner:
    """Runs a `FlightPlan` on a started station from the calling thread."""

    def __init__(self, station: Station, plan: FlightPlan,
                 on_progress: Callable[[StationSnapshot, Phase], None] | None = None,
                 rest_alt_m: float | None = None,
                 idle: Callable[[], None] | None = None, sysid: int = 1) -> None:
        self.station = station
        self.sysid = sysid  # the vehicle's system id, as failure lines name it
        # between looks at the station: sleep while its loop thread flies, or (lockstep) run
        # its next tick, the simulation included
        self.idle = idle or (lambda: time.sleep(POLL_S))
        # the truth's vertical origin is whatever the vehicle reported first; the flight starts
        # on the floor, where the centre of gravity is known to stand at rest_alt_m
        self.rest_alt_m = (station.config.estimator.rest_alt_m if rest_alt_m is None
                           else rest_alt_m)
        self.plan = plan
        self.phase = Phase.GROUND
        self.samples: list[FlightSample] = []
        self.on_progress = on_progress
        self._target: float | None = None
        # modes the vehicle may be in while armed; anything else (a failsafe LAND, say) ends
        # the flight with a clear message instead of scoring a flight nobody is flying
        self.expected_modes: set[int] = {FlightMode.STABILIZE}
        if station.config.hold_mode is HoldMode.CLIMB_RATE:
            self.expected_modes.add(FlightMode.ALT_HOLD)  # the climb-rate hold flies in it
        station.add_listener(self._sample)
        self.port = _FlyPort(self)
        self.launch = Launch({sysid: station}, self.port,
                             LaunchRules(rest_s=plan.rest_s, arm_timeout_s=plan.arm_timeout_s))

    def _sample(self, snap: StationSnapshot) -> None:
        est = snap.estimate
        self.samples.append(FlightSample(
            t_s=snap.t_s,
            phase=self.phase,
            setpoint_m=snap.alt_setpoint_m,
            target_m=self._target,
            est_alt_m=est.alt_m if est is not None else None,
            truth_alt_m=_truth_alt(snap),
            throttle_us=snap.command.throttle_us,
        ))

    # -------------------------------------------------------------- waiting
    def _why(self, snap: StationSnapshot) -> str:
        """The supervisor's last reason and the vehicle's recent words, for a failure line."""
        notes = [e.text for e in snap.events if e.text.startswith(f"{snap.state.value}:")]
        why = notes[-1] if notes else f"station {snap.state.value}"
        return why + vehicle_said(snap)

    def check(self, snap: StationSnapshot) -> None:
        if self.station.error is not None:
            raise FlightFailed(f"control loop stopped: {self.station.error}")
        allowed = PHASE_STATES.get(self.phase)
        if allowed is not None and snap.state not in allowed:
            raise FlightFailed(f"during {self.phase.value}: {self._why(snap)}")
        if (snap.armed and snap.vehicle_mode >= 0 and snap.vehicle_mode not in self.expected_modes
                and self.phase not in (Phase.GROUND, Phase.DONE)):
            raise FlightFailed(f"vehicle left the flight's mode for mode {snap.vehicle_mode} "
                               f"during {self.phase.value}: {self._why(snap)}")

    def wait(self, what: str, pred: Callable[[StationSnapshot], bool], timeout_s: float) -> None:
        """Wait `timeout_s` on the station's clock for `pred`; FlightFailed naming `what`."""
        clock = self.station.clock
        deadline = clock.now_s() + timeout_s
        while True:
            snap = self.station.snapshot(loop_stats=False)
            self.check(snap)
            if pred(snap):
                return
            if self.on_progress is not None:
                self.on_progress(snap, self.phase)
            if clock.now_s() >= deadline:
                raise FlightFailed(f"{what} did not happen within {timeout_s:g} s "
                                   f"({self._why(snap)})")
            self.idle()

    def pause(self, seconds: float) -> None:
        """Let `seconds` pass on the station's clock, watching for trouble."""
        clock = self.station.clock
        end = clock.now_s() + seconds
        while clock.now_s() < end:
            snap = self.station.snapshot(loop_stats=False)
            self.check(snap)
            if self.on_progress is not None:
                self.on_progress(snap, self.phase)
            self.idle()

    # -------------------------------------------------------------- the flight
    def arm(self) -> None:
        """STABILIZE, throttle at minimum, rest, arm: the launch every flight shares
        (`gcs.launch`); LaunchFailed, the vehicle disarmed, when it did not arm."""
        self.launch.arm()

    def fly(self) -> None:
        """Take off, settle, hold, step (if asked), land and disarm."""
        p = self.plan
        st = self.station
        self.arm()
        self.phase = Phase.ARMED
        if p.takeoff_delay_s > 0.0:
            self.pause(p.takeoff_delay_s)
        self._target = p.alt_m
        self.launch.ask_takeoff(p.alt_m, p.climb_mps)
        self.phase = Phase.TAKEOFF
        pose = st.snapshot(loop_stats=False).mocap
        if pose is not None:
            # with motion capture, hold the take-off spot and heading: without it the vehicle
            # drifts on its attitude noise and, in a room, ends up against a wall
            n, e, _ = pose.pos_n
            st.set_position_setpoint(PositionSetpoint(n, e, yaw_from_quat(pose.q_nb)))
        climb_s = p.alt_m / p.climb_mps
        self.wait("take-off to the hold altitude",
                   lambda s: s.state is SupervisorState.HOLD and s.estimate is not None
                   and abs(s.estimate.alt_m - p.alt_m) < 0.1
                   and s.alt_setpoint_m is not None and abs(s.alt_setpoint_m - p.alt_m) < 1e-6,
                   climb_s + 20.0)
        self.phase = Phase.SETTLE
        self.pause(p.settle_s)
        self.phase = Phase.HOLD
        self.pause(p.hold_s)
        if p.step_m:
            self.phase = Phase.STEP
            self._target = p.alt_m + p.step_m
            st.alt_hold(True, p.alt_m + p.step_m)  # a true step: the controller's own profile
            self.pause(p.step_observe_s)
        self.land()

    def land(self) -> None:
        """Descend under PC control to a few cm, then LAND touches down and disarms
        (`gcs.landing`, as for a team's vehicles); FlightFailed when either does not."""
        p = self.plan
        st = self.station
        self.phase = Phase.LAND
        self._target = 0.0
        snap = st.snapshot(loop_stats=False)
        if may_descend(snap):
            top = snap.estimate.alt_m if snap.estimate is not None else p.alt_m
            timeout_s = top / p.descent_mps + 15.0
            handover = p.handover_alt_m
            if st.config.hold_mode is HoldMode.CLIMB_RATE:
                # below the rangefinder's blind band the estimate does not see the descent
                handover = max(handover, st.config.climb.blind_alt_m)
            if not descend(st, self.port, self.sysid, p.descent_mps, timeout_s, handover):
                raise FlightFailed(f"descent did not happen within {timeout_s:g} s "
                                   f"({self._why(st.snapshot(loop_stats=False))})")
        self.expected_modes.add(FlightMode.LAND)
        if not hand_over(st, self._waited, (15.0, 3.0, 3.0, 3.0)):
            raise FlightFailed(f"the vehicle did not disarm in LAND nor on four requests "
                               f"({self._why(st.snapshot(loop_stats=False))})")
        self.phase = Phase.DONE

    def _waited(self, pred: Callable[[StationSnapshot], bool], timeout_s: float) -> bool:
        """`wait` as a yes or no (any failure it sees is a no)."""
        try:
            self.wait("disarm", pred, timeout_s)
        except FlightFailed:
            return False
        return True

    # -------------------------------------------------------------- scoring
    def summary(self, truth: Series | None = None) -> FlightSummary:
        """Score the flight from the samples and the station's statistics.

        `truth`: altitudes above the floor from an evaluation-only truth feed (the SITL's truth
        endpoint), stamped with the station's clock. Without it, the SIM_STATE reports the
        vehicle sent on its link, where it sent them."""
        snap = self.station.snapshot()
        hold = [s for s in self.samples if s.phase is Phase.HOLD and s.setpoint_m is not None]
        truth = truth if truth is not None else self._link_truth()
        score = score_hold([s.t_s for s in hold], [s.setpoint_m or 0.0 for s in hold],
                           [s.est_alt_m for s in hold], truth)
        e = score.errors
        ls = snap.loop
        stats = snap.link_stats
        return FlightSummary(
            rms_error_m=e.rms_m,
            max_error_m=e.max_m,
            error_source=score.source,
            mean_error_m=e.mean_m,
            std_error_m=e.std_m,
            truth_coverage=score.truth_coverage,
            truth_rate_hz=score.truth_rate_hz,
            step=self._step_metrics(score.source, truth),
            jitter_p50_ms=ls.jitter_p50_s * 1e3,
            jitter_p99_ms=ls.jitter_p99_s * 1e3,
            compute_p99_ms=ls.compute_p99_s * 1e3,
            overruns=ls.overruns,
            ticks=ls.ticks,
            rx_messages=stats.rx_messages,
            lost_messages=stats.lost_messages,
            corrupted=stats.bad_frames,
            hover_throttle=snap.hover_throttle,
            samples=tuple(self.samples),
            estimator=self.station.estimator.counts(),
        )

    def truth_origin_m(self) -> float | None:
        """Offset to subtract from SIM_STATE truth altitudes (relative to the vehicle's first
        report): from the samples on the floor, where the centre of gravity stands at
        `rest_alt_m`. A truth feed measured from the floor needs none."""
        return _truth_origin([s.truth_alt_m for s in self.samples if s.phase is Phase.GROUND],
                             self.rest_alt_m)

    def _link_truth(self) -> Series | None:
        """The SIM_STATE reports in the samples, one point per report, above the floor."""
        origin = self.truth_origin_m()
        if origin is None:
            return None
        samples = tuple(self.samples)  # the loop thread may append while we read
        reports = distinct_reports([s.t_s for s in samples], [s.truth_alt_m for s in samples])
        return Series(reports.t_s, reports.alt_m - origin)

    def _alt(self, source: str, truth: Series | None, t0_s: float, t1_s: float) -> Series | None:
        """The altitude the score's source saw over [t0_s, t1_s]."""
        if source == TRUTH and truth is not None:
            return truth.between(t0_s, t1_s)
        if source == ESTIMATE:
            part = [s for s in self.samples if t0_s <= s.t_s <= t1_s and s.est_alt_m is not None]
            return Series.of([s.t_s for s in part], [s.est_alt_m or 0.0 for s in part])
        return None

    def _step_metrics(self, source: str, truth: Series | None) -> StepMetrics | None:
        p = self.plan
        step = [s for s in self.samples if s.phase is Phase.STEP]
        if not p.step_m or not step:
            return None
        series = self._alt(source, truth if truth is not None else self._link_truth(),
                           step[0].t_s, step[-1].t_s)
        if series is None:
            return None
        return step_response(series, step[0].t_s, p.alt_m + p.step_m, p.step_m, p.step_band_m,
                             p.step_smooth_s)
