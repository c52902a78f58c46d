"""What every altitude estimator shares: the driver (sonar judgement: `sonar_readings`)."""

from __future__ import annotations

import math
from abc import abstractmethod
from collections import deque
from collections.abc import Sequence
from dataclasses import replace

from firmware_link.records import Attitude, Imu, Rangefinder
from gcs.estimation.catch_up import CatchUp, EstimatorTick, average_imu
from gcs.estimation.control import (
    control_correct,
    control_follow,
    control_predict,
    control_start,
)
from gcs.estimation.estimate import AltEstimate, EstimatorCounts, SonarStatus
from gcs.estimation.inputs import vertical_accel_up_mps2
from gcs.estimation.params import EstimatorParams
from gcs.estimation.repeat_motion import RepeatMotion
from gcs.estimation.sonar_readings import SonarReadings

LIFTOFF_ALT_SIGMA_M = 0.03
LIFTOFF_VEL_SIGMA_MPS = 0.1


class AltEstimator(SonarReadings):
    """Common driver: time step, attitude, accelerometer and sonar conditioning, gating.

    Subclasses implement the propagation (`_predict`), the correction (`_correct`) and the gate
    test (`_gate`)."""

    name = "base"

    def __init__(self, params: EstimatorParams | None = None) -> None:
        self.params = params or EstimatorParams()
        self._t_s: float | None = None
        self._roll = 0.0
        self._pitch = 0.0
        self._acc_up = 0.0
        self._imu_t_s = -math.inf
        self._last_sonar_t_s = -math.inf
        self._sonar_heard_s = -math.inf  # the last sonar record of any kind
        self._last_distance: float | None = None
        self._last_new_t_s = -math.inf  # tick of the last reading counted as new
        self._last_new_rx_s = -math.inf  # its message's receive stamp
        self._lost_at_new = 0  # the link's lost frames at the last new reading
        # How far the vehicle has moved since the altitude the current sonar value measured:
        # the sonar's own repeats must not pin the estimate that judges them (a stale value
        # fused as new holds the filter still)
        self._repeat_motion = RepeatMotion()
        # the accelerometer's own climb rate, leaking away (see climb_vel_mps)
        self._climb_vel_mps = 0.0
        self._value_rx_s = -math.inf  # when the current value first arrived
        self._doubt_until_s = -math.inf  # repeats are not readings until then (see sonar_doubt_s)
        self._reading_late = False  # whether the reading just used was taken as a late echo
        self._history: deque[tuple[float, float]] = deque()  # (t_s, alt_m) after each predict
        self._rejected: deque[tuple[float, float]] = deque()  # (t_s, sonar alt), consecutive
        self._rejected_total = 0
        self._initialised = False
        self._reject_run_start_s = 0.0
        self._reject_seen_s = -math.inf  # last rejected reading, or a repeat of it
        self._catch_up = CatchUp()
        self._control = control_start(0.0, 0.0, 0.1**2)
        # the hold's filter on the accelerometer alone, not the commands: a second velocity for
        # the repeat test that, unlike the hold's, a rerun with other gains leaves as it was
        self._twin = control_start(0.0, 0.0, 0.1**2)
        self._command_acc: float | None = None
        self._command_lagged = self._command_residual = 0.0
        self._airborne = False  # the station knows the vehicle is off the floor (update)
        self._blind = False  # a reading below the minimum range came since the last in range

    @abstractmethod
    def _predict(self, acc_up_mps2: float, dt_s: float) -> None: ...

    def update(
        self,
        imu: Imu | None,
        sonar: Rangefinder | None,
        attitude: Attitude | None,
        t_s: float,
        at_rest: bool = False,
        baro_alt_m: float | None = None,
        airborne: bool = False,
    ) -> AltEstimate:
        """Advance to `t_s` with the newest samples (None = nothing new since the last step).

        `at_rest`: the vehicle is known to stand still (disarmed). With the sonar reading the
        floor, the filter then knows the vertical velocity is 0, which pins the accelerometer
        bias before take-off instead of leaving it to the sonar in flight.
        `baro_alt_m`: a new barometric altitude (any reference), for filters that fuse it.
        `airborne`: the station knows the vehicle is off the floor (its take-off saw it lift
        and it holds it above the sonar's blind band): a reading below the minimum range is
        then the blind band (`SonarStatus.BLIND`), never the floor."""
        p = self.params
        self._airborne = airborne
        if not airborne:
            self._blind = False
        if attitude is not None:
            self._roll, self._pitch = attitude.roll_rad, attitude.pitch_rad
        if imu is not None:
            self._acc_up = vertical_accel_up_mps2(imu.acc_b, self._roll, self._pitch)
            self._imu_t_s = t_s
        elif t_s - self._imu_t_s > p.imu_stale_s and self._t_s is not None:
            self._acc_up = self._state()[2]  # the bias alone: no acceleration
        dt = 0.0 if self._t_s is None else min(max(t_s - self._t_s, 0.0), p.max_dt_s)
        self._t_s = t_s
        if dt > 0.0:
            self._predict(self._acc_up, dt)
            a = self._acc_up - self._state()[2]
            self._repeat_motion.propagate(a, dt)
            self._climb_vel_mps += (a - self._climb_vel_mps / p.climb_leak_s) * dt
            control_predict(self._control, self._control_accel(a, dt), dt,
                            p.control_accel_sigma_mps2)
            control_predict(self._twin, a, dt, p.control_accel_sigma_mps2)
        alt_before = self._state()[0]
        self._history.append((t_s, alt_before))
        while self._history[0][0] < t_s - p.history_s:
            self._history.popleft()

        if at_rest:
            self._climb_vel_mps = 0.0
        status = SonarStatus.NONE
        innovation = 0.0
        if sonar is not None:
            # only after a rejection run as long as the steady-reading re-base asks for: in a
            # climb a short run of rejected readings can agree too, and re-basing on a move
            # would leave the hold displaced by it
            long_run = bool(self._rejected) and (
                t_s - self._reject_run_start_s >= p.reacquire_min_s)
            tail = [z for _, z in self._rejected][-p.reacquire_count:] if long_run else []
            status, innovation = self._sonar(sonar, t_s, alt_before)
            self._sonar_heard_s = t_s
            if status is SonarStatus.USED and self._leapt_onto(tail, alt_before):
                status = SonarStatus.REACQUIRED
        if at_rest and self._state()[0] < p.ground_alt_m:
            self._at_rest()
        # Downwash off the surface below biases the barometer. Which surface: the estimate's,
        # or, past a table's edge, the floor the sonar steadily sees far below it (the readings
        # the estimate rejects while it still measures from the table top, until it re-bases):
        # shutting the barometer out would leave it to the accelerometer alone for seconds.
        # Only steady readings: over carpet a lost echo reads long now and then, and near the
        # floor on take-off that let the downwash into the barometer's offset.
        alt = self._state()[0]
        clear = alt >= p.baro_min_alt_m or self._steady_far_below(alt)
        if baro_alt_m is not None and self._initialised and (at_rest or clear):
            self._baro(baro_alt_m, coasting=t_s - self._last_sonar_t_s > p.stale_after_s)
        alt, vel, bias, sigma = self._state()
        age = t_s - self._last_sonar_t_s
        ctl = self._control
        # No sonar record at all while the accelerometer's keep coming: the link lost them, and
        # the hold coasts on its command a while. A sensor that kept sending what the estimate
        # did not take (a carpet's repeats, refused late echoes) is the estimator's to bridge,
        # on its barometer too; so is a stream that stopped whole (a vehicle fallen behind,
        # whose burst the catch-up replays: a command it has not flown yet predicts nothing).
        # Alive: a sample within half the stale time, as a lossy link still brings one every
        # few ticks and a stall none for the whole gap.
        lost = (self._sonar_heard_s <= self._last_sonar_t_s
                and t_s - self._imu_t_s < 0.5 * p.stale_after_s)
        if (status in (SonarStatus.GROUND, SonarStatus.REACQUIRED, SonarStatus.UNBLINDED)
                or at_rest
                or age > (p.control_coast_s if lost else p.stale_after_s)
                or not self._initialised):
            control_follow(ctl, alt, vel, sigma)
            control_follow(self._twin, alt, vel, sigma)
        elif status is SonarStatus.USED:
            # the reading as the estimator took it: late echoes moved to the present
            r = p.sonar_sigma_m**2 + p.sonar_resolution_m**2 / 12.0
            control_correct(ctl, alt_before + innovation, r)
            control_correct(self._twin, alt_before + innovation, r)
        return AltEstimate(
            t_s=t_s,
            alt_m=alt,
            vel_mps=vel,
            acc_mps2=self._acc_up - bias,
            bias_mps2=bias,
            sonar_used=status in (SonarStatus.USED, SonarStatus.GROUND, SonarStatus.REACQUIRED,
                                  SonarStatus.UNBLINDED),
            sonar_status=status,
            innovation_m=innovation,
            sonar_age_s=age,
            coasting=age > p.stale_after_s,
            alt_sigma_m=sigma,
            rejected_total=self._rejected_total,
            control_alt_m=ctl[0],
            control_vel_mps=ctl[1],
        )

    def _control_accel(self, measured: float, dt: float) -> float:
        p = self.params
        cmd = self._command_acc
        if cmd is None or p.command_blend_tc_s <= 0.0:
            self._command_lagged, self._command_residual = measured, 0.0
            return measured
        self._command_lagged += (cmd - self._command_lagged) * dt / (p.command_lag_s + dt)
        resid = measured - self._command_lagged
        self._command_residual += (resid - self._command_residual) * dt / (
            p.command_blend_tc_s + dt)
        return self._command_lagged + self._command_residual

    def update_tick(
        self,
        imus: Sequence[Imu] | Imu | None,
        sonars: Sequence[Rangefinder],
        attitude: Attitude | None,
        t_s: float,
        at_rest: bool = False,
        baro_alt_m: float | None = None,
        command_acc_mps2: float | None = None,
        airborne: bool = False,
        liftoff: tuple[float, float] | None = None,
    ) -> AltEstimate:
        """One control tick with every sample it brought (see `catch_up` for late bursts).

        `command_acc_mps2`: the vertical acceleration the last stick command sent asks of the
        vehicle (None when the station does not fly the throttle). `airborne`: see `update`.
        `liftoff`: the station's take-off felt the vehicle leave the floor at the last tick,
        at this (altitude m, velocity m/s) by its accelerometer: the estimate, held on the
        floor by the zeros of a sonar that is blind there, starts over from it."""
        samples = () if imus is None else (imus,) if isinstance(imus, Imu) else tuple(imus)
        inputs = EstimatorTick(t_s, samples, tuple(sonars), attitude, at_rest, baro_alt_m,
                               command_acc_mps2, airborne, liftoff)
        est = self._catch_up.tick(self, inputs, self._run_tick)
        assert isinstance(est, AltEstimate)
        return est

    @property
    def burst_replays(self) -> int:
        """Late bursts integrated at their samples' own times."""
        return self._catch_up.replays

    @property
    def imu_dropped(self) -> int:
        """IMU samples the link delivered twice (integrated once)."""
        return self._catch_up.dropped

    def counts(self) -> EstimatorCounts:
        c = self._catch_up
        return EstimatorCounts(self._rejected_total, c.replays, c.dropped, c.implausible)

    def snapshot(self) -> object:
        """The filter's state, to be put back by `restore` (its containers copied)."""
        return {k: _copied(v) if isinstance(v, _CONTAINERS) else v  # taken every tick
                for k, v in vars(self).items() if k != "_catch_up"}

    def restore(self, state: object) -> None:
        assert isinstance(state, dict)
        vars(self).update({k: _copied(v) for k, v in state.items()})

    def _run_tick(self, tick: EstimatorTick) -> AltEstimate:
        """`update` with the tick's IMU samples averaged and its first sonar reading, then
        each later reading.

        A tick can bring two readings (the sonar's rate beats against the loop's). When one of
        them re-based the estimate on another surface (or ended the blind band), the tick's
        estimate says so, whatever the later one did: the controller must move its setpoint by
        the jump, or it holds a table's height as an error and dives for the surface it left.
        """
        sonars = tick.sonars
        self._command_acc = tick.command_acc_mps2
        if tick.liftoff is not None:
            self._lifted_off(*tick.liftoff)
        est = self.update(average_imu(tick.imus), sonars[0] if sonars else None, tick.attitude,
                          tick.t_s, at_rest=tick.at_rest, baro_alt_m=tick.baro_alt_m,
                          airborne=tick.airborne)
        rebased = est.sonar_status is SonarStatus.REACQUIRED
        unblinded = est.sonar_status is SonarStatus.UNBLINDED
        for extra in sonars[1:]:
            est = self.update(None, extra, None, tick.t_s, airborne=tick.airborne)
            rebased = rebased or est.sonar_status is SonarStatus.REACQUIRED
            unblinded = unblinded or est.sonar_status is SonarStatus.UNBLINDED
        if rebased and est.sonar_status is not SonarStatus.REACQUIRED:
            est = replace(est, sonar_status=SonarStatus.REACQUIRED, sonar_used=True)
        elif unblinded and est.sonar_status is not SonarStatus.UNBLINDED:
            # the hold moves its climb by the correction (as by a re-base): it must hear of it
            est = replace(est, sonar_status=SonarStatus.UNBLINDED, sonar_used=True)
        return est

    def _lifted_off(self, alt_m: float, vel_mps: float) -> None:
        """The vertical state starts over where the take-off felt the vehicle leave the floor
        (a few cm, known to a few cm; its velocity to 0.1 m/s: the accelerometer's integral)."""
        p = self.params
        self._seed(alt_m, vel_mps, LIFTOFF_ALT_SIGMA_M, LIFTOFF_VEL_SIGMA_MPS)
        self._climb_vel_mps = max(self._climb_vel_mps, vel_mps, p.climb_vel_mps)
        sigma = self._state()[3]
        control_follow(self._control, alt_m, vel_mps, sigma)
        control_follow(self._twin, alt_m, vel_mps, sigma)

    @abstractmethod
    def _baro(self, baro_alt_m: float, coasting: bool) -> None:
        """Fuse a barometric altitude (the baselines do not: they are sonar and IMU only)."""

    @abstractmethod
    def _at_rest(self) -> None:
        """The vehicle stands on the floor: its vertical velocity is 0."""


_CONTAINERS = (deque, list, RepeatMotion)


def _copied(v: object) -> object:
    """A copy of a filter attribute that shares nothing mutable with it."""
    if isinstance(v, list):
        return [_copied(x) if isinstance(x, _CONTAINERS) else x for x in v]
    return deque(v) if isinstance(v, deque) else v.copy() if isinstance(v, RepeatMotion) else v
