"""How far the vehicle has moved since the sonar's current value was read.

The telemetry stream repeats the sonar's latest reading whether or not the sensor has replaced
it; a repeat is a new ping that landed in the same centimetre only while the vehicle has not
moved further than a repeat allows. That motion is dead-reckoned on the accelerometer from the
velocity at the value's first arrival, twice: from the estimator's velocity, and from that of
a twin of the hold's filter (gcs/estimation/control.py) on the accelerometer alone, which
follows the sonar more closely. A repeat is taken as stale only when both say the vehicle
moved: a velocity error of the estimator's alone (-0.12 m/s in a steady hover after a few
noisy accelerometer samples on a lossy link) then no longer makes the sonar look stale and
leaves the filter coasting on that error (lockstep apm25, 33 % of frames lost for 60 s: worst
hold error 3.5-18.8 cm over 20 seeds on one velocity, 3.5-8.8 cm on both).
"""

from __future__ import annotations


class RepeatMotion:
    """Two dead-reckoned displacements since the current sonar value: from the estimator's
    velocity and from the tighter filter's."""

    __slots__ = ("_move", "_vel")

    def __init__(self) -> None:
        self._move = [0.0, 0.0]
        self._vel = [0.0, 0.0]

    def restart(self, move_m: float, vel_mps: float, tight_vel_mps: float) -> None:
        """A new value: the vehicle has moved `move_m` since it was measured (a late echo's
        climb since its ping, else 0), at these velocities now."""
        self._move = [move_m, move_m]
        self._vel = [vel_mps, tight_vel_mps]

    def propagate(self, acc_mps2: float, dt_s: float) -> None:
        """Advance `dt_s` on the bias-corrected upward acceleration."""
        for i in (0, 1):
            self._move[i] += (self._vel[i] + 0.5 * acc_mps2 * dt_s) * dt_s
            self._vel[i] += acc_mps2 * dt_s

    def copy(self) -> RepeatMotion:
        """An independent copy (for the estimator's snapshots)."""
        c = RepeatMotion()
        c._move, c._vel = self._move[:], self._vel[:]
        return c

    def moved_m(self) -> float:
        """The smaller of the two displacements' sizes."""
        return min(abs(self._move[0]), abs(self._move[1]))
