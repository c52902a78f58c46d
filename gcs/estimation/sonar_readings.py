"""How an altitude estimator takes a sonar reading: new or repeated, prompt or a late echo,
gated, rejected, or agreeing with others on a surface the estimate must re-base on.

`SonarReadings` is the part of `AltEstimator` (gcs.estimation.base) that judges readings; the
filter's own update and its state are declared here and owned there.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import deque

from firmware_link.records import Rangefinder
from gcs.estimation.control import ControlState
from gcs.estimation.estimate import SonarStatus
from gcs.estimation.inputs import line_at, sonar_altitude_m
from gcs.estimation.params import EstimatorParams
from gcs.estimation.repeat_motion import RepeatMotion


class SonarReadings(ABC):
    """Sonar reading judgement over the estimator's state (set by `AltEstimator.__init__`)."""

    params: EstimatorParams
    _roll: float
    _pitch: float
    _climb_vel_mps: float
    _last_sonar_t_s: float
    _last_distance: float | None
    _last_new_t_s: float
    _last_new_rx_s: float
    _lost_at_new: int
    _repeat_motion: RepeatMotion
    _value_rx_s: float
    _doubt_until_s: float
    _reading_late: bool
    _history: deque[tuple[float, float]]
    _rejected: deque[tuple[float, float]]
    _rejected_total: int
    _initialised: bool
    _reject_run_start_s: float
    _reject_seen_s: float
    _twin: ControlState
    _airborne: bool
    _blind: bool

    @abstractmethod
    def _gate(self, z_alt_m: float, extra_var_m2: float = 0.0) -> bool:
        """True when the reading (with `extra_var_m2` more noise than usual) passes the gate."""

    @abstractmethod
    def _correct(self, z_alt_m: float, t_s: float, extra_var_m2: float = 0.0) -> None: ...

    @abstractmethod
    def _reset_alt(self, alt_m: float) -> None: ...

    @abstractmethod
    def _seed(self, alt_m: float, vel_mps: float, alt_sigma_m: float,
              vel_sigma_mps: float) -> None:
        """Start the vertical state over at this altitude and velocity (and their sigmas)."""

    def _widen_alt(self, var_m2: float) -> None:  # noqa: B027 - filters without a variance
        """Add `var_m2` to the altitude's variance (a coast known to have drifted that much)."""

    @abstractmethod
    def _state(self) -> tuple[float, float, float, float]:
        """(alt_m, vel_mps, bias_mps2, alt_sigma_m)."""

    def _leapt_onto(self, rejected_tail: list[float], alt_before: float) -> bool:
        """The reading just used moved the estimate a surface step onto the surface that the
        readings rejected just before it agreed on.

        Rejections of a steady surface (the floor past a table's edge) leave the filter
        coasting and its gate wide, until one of those readings passes and moves the estimate
        by a table's height: a re-base, not a climb, and the controller must hear it as one or
        it dives for the surface it left. A leap after lost or late echoes (carpet) is not one:
        it corrects a drift, a move the hold must make.
        """
        p = self.params
        alt = self._state()[0]
        if abs(alt - alt_before) < p.surface_step_m or len(rejected_tail) < p.reacquire_count:
            return False
        lo, hi = min(rejected_tail), max(rejected_tail)
        return hi - lo <= p.reacquire_spread_m and lo - p.reacquire_spread_m <= alt <= (
            hi + p.reacquire_spread_m)

    def _steady_far_below(self, alt_m: float) -> bool:
        """The rejected readings of late agree on a surface far below the estimate's."""
        p = self.params
        recent = [z for _, z in self._rejected]
        return (len(recent) >= p.reacquire_count
                and max(recent) - min(recent) <= p.reacquire_spread_m
                and min(recent) >= max(p.baro_min_alt_m, alt_m + p.surface_step_m))

    def _alt_at(self, t_s: float) -> float:
        """The estimate as it was at `t_s` (the oldest kept when older)."""
        for t, alt in reversed(self._history):
            if t <= t_s:
                return alt
        return self._history[0][1]

    def _is_new_reading(self, d: float, t_s: float) -> bool:
        """Whether a sonar message carries a reading the sensor took since the last one.

        A changed value is new. A repeated one is new too once the sensor has had time to
        ping again (`sonar_repeat_s`), as whole-centimetre readings of a steady hover mostly
        repeat: with 3 mm of noise 85 % of the pings read the centimetre before. Only when the
        vehicle has since moved further than a repeat allows is it the stream re-sending a
        reading the sensor has not replaced, as over carpet while an echo is late."""
        p = self.params
        if d != self._last_distance:
            return True
        if t_s - self._last_new_rx_s < p.sonar_repeat_s or t_s < self._doubt_until_s:
            return False
        lasted_s = t_s - self._value_rx_s
        return (self._repeat_motion.moved_m()
                <= p.sonar_stale_move_m + p.sonar_stale_drift_mps * lasted_s)

    def _sonar(self, sonar: Rangefinder, t_s: float, alt_pred: float) -> tuple[SonarStatus, float]:
        d = sonar.distance_m if sonar.valid else 0.0
        # the message's own arrival (receive stamp) times the repeat test; the tick's time
        # (`t_s`) times everything the filter does with the reading
        fresh = self._is_new_reading(d, sonar.t_s)
        changed = d != self._last_distance
        prev_new_t_s = self._last_new_t_s
        # A sensor's silence is seen only in a stream that arrived whole: after the link lost
        # frames, a new reading is the sensor's latest (its ping is now), not a late echo of a
        # ping sent when the last reading before the gap arrived
        ping_t_s = prev_new_t_s if sonar.link_lost == self._lost_at_new else t_s
        if fresh:
            self._last_distance, self._last_new_t_s = d, t_s
            self._last_new_rx_s, self._lost_at_new = sonar.t_s, sonar.link_lost
        result = self._use_reading(sonar, d, fresh, ping_t_s, t_s, alt_pred)
        if changed and fresh:
            # this value measured the altitude of now for a prompt reading, of its ping for a
            # late echo (the clone still holds that until _on_ping)
            alt, vel = self._state()[:2]
            self._value_rx_s = sonar.t_s
            self._repeat_motion.restart(
                self._late_shift(prev_new_t_s, alt)[0] if self._reading_late else 0.0,
                vel, self._twin[1])
        if fresh:
            # the HC-SR04 sends its next ping as soon as an echo (or its timeout) is in
            self._on_ping(t_s)
        return result

    def _on_ping(self, t_s: float) -> None:  # noqa: B027 - optional: only cloning filters need it
        """A new ping went out about now; filters that can, remember the state at this time."""

    def _late_shift(self, ping_t_s: float, alt_pred: float) -> tuple[float, float]:
        """(climb since the ping, its variance) to move a late echo to the present."""
        return alt_pred - self._alt_at(ping_t_s), self.params.late_sigma_m**2

    def _gate_late(self, z_ping_m: float, ping_t_s: float, alt_pred: float) -> bool:
        shift, var = self._late_shift(ping_t_s, alt_pred)
        return self._gate(z_ping_m + shift, var)

    def _correct_late(self, z_ping_m: float, ping_t_s: float, alt_pred: float, t_s: float) -> None:
        shift, var = self._late_shift(ping_t_s, alt_pred)
        self._correct(z_ping_m + shift, t_s, var)

    def _use_reading(
        self, sonar: Rangefinder, d: float, fresh: bool, ping_t_s: float, t_s: float,
        alt_pred: float,
    ) -> tuple[SonarStatus, float]:
        p = self.params
        self._reading_late = False
        in_range = sonar.valid and p.sonar_min_m <= d <= p.sonar_max_m
        if not in_range and self._airborne and d < p.sonar_min_m:
            # Off the floor (the station saw it lift) and under the minimum range: the sensor
            # is blind, not on the floor. Pinning the estimate to the floor here held it there
            # while the take-off ramp ran on (real 4.7: seen 1.15 s late, 0.3 m up, 1.3 m/s).
            self._blind = True
            return SonarStatus.BLIND, 0.0
        if not in_range:
            if (d <= p.sonar_min_m and alt_pred < p.ground_alt_m
                    and self._climb_vel_mps < p.climb_vel_mps):
                # the HC-SR04 reads 0 below its minimum: on the floor, that *is* the altitude
                self._correct(p.rest_alt_m, t_s)
                self._initialised = True
                self._last_sonar_t_s = t_s
                return SonarStatus.GROUND, p.rest_alt_m - alt_pred
            if fresh and self._initialised:
                # a lost echo in the air: carpet (or beyond range), where repeats mislead
                self._doubt_until_s = sonar.t_s + p.sonar_doubt_s
            return SonarStatus.INVALID, 0.0
        if not fresh:
            if self._rejected and d == self._last_distance:
                # the stream repeating a disagreeing reading: the disagreement goes on (with
                # whole centimetres a steady floor past a table's edge mostly repeats)
                self._reject_seen_s = t_s
            return SonarStatus.DUPLICATE, 0.0
        z = sonar_altitude_m(d + p.sonar_offset_m + p.sonar_bias_m, self._roll, self._pitch)
        if self._blind:
            return self._unblinded(z, t_s, alt_pred)
        # The HC-SR04 does not ping again before an echo is back, so a reading after a long
        # silence is a late echo of a ping sent about when the previous reading arrived
        # (`ping_t_s`; carpet, thesis ch. 7): it measures the altitude of then, not of now.
        late = self._initialised and p.late_gap_s < t_s - ping_t_s <= p.late_max_s
        self._reading_late = late
        if late and abs(z - alt_pred) > p.sonar_stale_move_m:
            # after a silence, the altitude of long ago: the sensor waits for late echoes here
            self._doubt_until_s = sonar.t_s + p.sonar_doubt_s
        z_now = z + self._late_shift(ping_t_s, alt_pred)[0] if late else z
        innovation = z_now - alt_pred
        if not self._initialised:
            # the first in-range reading sets the altitude; nothing to gate it against yet
            self._initialised = True
            self._reset_alt(z)
            self._last_sonar_t_s = t_s
            return SonarStatus.USED, innovation
        passed = self._gate_late(z, ping_t_s, alt_pred) if late else self._gate(z)
        if passed:
            self._rejected.clear()
            if late:
                self._correct_late(z, ping_t_s, alt_pred, t_s)
            else:
                self._correct(z, t_s)
            self._last_sonar_t_s = t_s
            return SonarStatus.USED, innovation
        self._rejected_total += 1
        if self._rejected and t_s - self._reject_seen_s > p.stale_after_s:
            self._rejected.clear()  # not consecutive: readings were accepted or absent between
        if not self._rejected:
            self._reject_run_start_s = t_s
        self._rejected.append((t_s, z_now))
        self._reject_seen_s = t_s
        while self._rejected[0][0] < t_s - p.reacquire_window_s:
            self._rejected.popleft()
        believed = self._reacquired_at(t_s, z_now)
        if believed is None:
            return SonarStatus.REJECTED, innovation
        self._reset_alt(believed)
        self._rejected.clear()
        self._last_sonar_t_s = t_s
        return SonarStatus.REACQUIRED, believed - alt_pred

    def _unblinded(self, z: float, t_s: float, alt_pred: float) -> tuple[SonarStatus, float]:
        """The first in-range reading after the blind band. The estimate crossed the band on
        the accelerometer alone, so a gate as narrow as a steady hover's would refuse the
        sonar's first word on where the vehicle is (real 4.7: the first readings failed it and
        the estimate lagged truth by 24-32 cm); it is taken through a gate as wide as the band
        (a carpet's far echo still fails that), and, with its altitude variance widened by the
        disagreement, moves the estimate onto it. Its timing is not a late echo's: the band's
        zeros repeat, and their first arrival is not this reading's ping."""
        p = self.params
        self._reading_late = False
        innovation = z - alt_pred
        if not self._initialised:
            self._initialised = True
            self._blind = False
            self._reset_alt(z)
            self._last_sonar_t_s = t_s
            return SonarStatus.UNBLINDED, innovation
        if not self._gate(z, p.sonar_min_m**2):
            self._rejected_total += 1
            return SonarStatus.REJECTED, innovation
        self._blind = False
        self._rejected.clear()
        self._widen_alt(innovation * innovation)
        self._correct(z, t_s)
        self._last_sonar_t_s = t_s
        return SonarStatus.UNBLINDED, innovation

    def _reacquired_at(self, t_s: float, z_now: float) -> float | None:
        """The altitude to reset to when the sonar has disagreed for longer than any late echo
        lasts and now tells one story (a box under the vehicle, or an estimate that drifted
        while coasting): it reads steadily (`z_now`), or moves on a straight line; else None."""
        p = self.params
        if t_s - self._reject_run_start_s < p.reacquire_min_s:
            return None
        recent = [r for t, r in self._rejected if t >= t_s - p.reacquire_steady_s]
        if len(recent) >= p.reacquire_count and max(recent) - min(recent) <= p.reacquire_spread_m:
            return z_now
        return self._rejected_on_a_line(t_s)

    def _rejected_on_a_line(self, t_s: float) -> float | None:
        """The altitude now of the rejected readings of the last `reacquire_min_s`, when they
        lie on one straight line in time; else None."""
        p = self.params
        pts = [(t, z) for t, z in self._rejected if t >= t_s - p.reacquire_min_s]
        if len(pts) < p.reacquire_track_count:
            return None
        return line_at(pts, t_s, p.reacquire_track_rms_m)
