"""HC-SR04 ultrasonic ranger looking down: pings at ≈ 20 Hz, readings arrive after the echo.

Each ping measures the slant range along body +z to the first surface (floor or box top). The
reading is delivered when its echo would be back (2·d / 340 m/s later); the sensor does not ping
again until then, like the real one, which blocks on its echo pin. No echo (beyond 4 m, or lost)
ends the pulse after the ~38 ms timeout and gives an invalid reading; a surface closer than
2 cm gives no reading at all (its echo comes back while the transducer still rings from the
burst), so on the floor the sonar reads invalid (distance 0) whatever its noise, as the real
firmwares report 0 on the ground. Over carpet (thesis Ch. 7) some echoes come back late, up to
1.2 s, still carrying the range of their ping, and some never return.
"""

from __future__ import annotations

import numpy as np

from sitl.sensor_params import SonarParams
from sitl.tick_record import tick_record
from sitl.world import FloorMaterial


@tick_record
class SonarSample:
    """A sonar reading; distance_m is 0 when not valid."""

    t_s: float  # when the reading arrived
    distance_m: float
    valid: bool
    ping_t_s: float  # when the ping that produced it went out


class SonarModel:
    """Ping scheduling, echo timing and the reading's imperfections."""

    def __init__(self, params: SonarParams, rng: np.random.Generator, noise: bool = True) -> None:
        self.params = params
        self.rng = rng
        self.noise = noise
        self.next_ping_t_s = 0.0
        self._in_flight: SonarSample | None = None
        self._ready: SonarSample | None = None
        self.late_echoes = 0
        self.dropouts = 0

    def ping(self, t_s: float, range_m: float | None, surface: FloorMaterial) -> None:
        """Send a ping at t_s; range_m is the true slant range (None: nothing within max_m)."""
        prm = self.params
        self._deliver(t_s)
        rng = self.rng
        if range_m is None or range_m > prm.max_m:
            arrival, reading, valid = t_s + prm.timeout_s, 0.0, False
        else:
            arrival = t_s + 2.0 * range_m / prm.speed_of_sound_mps
            reading, valid = range_m, True
            if self.noise:
                if surface is FloorMaterial.CARPET:
                    draw = rng.random()
                    if draw < prm.carpet_dropout_prob:
                        self.dropouts += 1
                        arrival, reading, valid = t_s + prm.timeout_s, 0.0, False
                    elif draw < prm.carpet_dropout_prob + prm.carpet_late_prob:
                        self.late_echoes += 1
                        arrival += rng.uniform(0.0, prm.carpet_max_delay_s)
                if valid:
                    if rng.random() < prm.outlier_prob:
                        reading = rng.uniform(prm.min_m, prm.max_m)
                    else:
                        reading += prm.noise_m * rng.standard_normal()
            # the true range decides below the minimum: noise cannot lift a reading into range
            if valid and (range_m < prm.min_m or not prm.min_m <= reading <= prm.max_m):
                reading, valid = 0.0, False
        self._in_flight = SonarSample(t_s=arrival, distance_m=reading, valid=valid, ping_t_s=t_s)
        self.next_ping_t_s = max(t_s + 1.0 / prm.rate_hz, arrival)

    def _deliver(self, t_s: float) -> None:
        f = self._in_flight
        if f is not None and f.t_s <= t_s:
            self._ready = f
            self._in_flight = None

    def poll(self, t_s: float) -> SonarSample | None:
        """The newest reading that arrived by t_s and was not returned before, else None."""
        self._deliver(t_s)
        out, self._ready = self._ready, None
        return out
