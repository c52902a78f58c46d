"""How far the vehicle has moved since the sonar's current value was read.

The telemetry stream repeats the sonar's latest reading whether or not the sensor has replaced
it; a repeat is a new ping that landed in the same centimetre only while the vehicle has not
moved further than a repeat allows. That motion is dead-reckoned from the velocity at the
value's first arrival, twice: on the estimator's own velocity and acceleration, and on the
hold's filter's (gcs/estimation/control.py), which follows the sonar more closely and takes
the rotors' vibration in a few times weaker. A repeat is taken as stale only when both agree
the vehicle moved: a velocity error of either alone (the estimator's, at -0.12 m/s in a steady
hover after a few noisy accelerometer samples on a lossy link) then no longer makes the sonar
look stale and leaves the filter coasting on that error (lockstep apm25, 33 % of frames lost
for 60 s: worst hold error 4.5-18.8 cm over 20 seeds with one velocity, 3.5-8.8 cm with both).
"""

from __future__ import annotations


class RepeatMotion:
    """Two dead-reckoned displacements since the current sonar value: (estimator, hold)."""

    __slots__ = ("_move", "_vel")

    def __init__(self) -> None:
        self._move = [0.0, 0.0]
        self._vel = [0.0, 0.0]

    def restart(self, move_m: float, vel_mps: float, control_vel_mps: float) -> None:
        """A new value: the vehicle has moved `move_m` since it was measured (a late echo's
        climb since its ping, else 0), at these velocities now."""
        self._move = [move_m, move_m]
        self._vel = [vel_mps, control_vel_mps]

    def propagate(self, acc_mps2: float, control_acc_mps2: float, dt_s: float) -> None:
        """Advance `dt_s` on each filter's bias-corrected upward acceleration."""
        for i, a in enumerate((acc_mps2, control_acc_mps2)):
            self._move[i] += (self._vel[i] + 0.5 * a * dt_s) * dt_s
            self._vel[i] += a * dt_s

    def copy(self) -> RepeatMotion:
        """An independent copy (for the estimator's snapshots)."""
        c = RepeatMotion()
        c._move, c._vel = self._move[:], self._vel[:]
        return c

    def moved_m(self) -> float:
        """The smaller of the two displacements' sizes."""
        return min(abs(self._move[0]), abs(self._move[1]))
