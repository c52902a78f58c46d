"""Off-board motion capture: noisy poses captured at 100 Hz, delivered after a fixed latency."""

from __future__ import annotations

import collections

import numpy as np

from sitl.rotation import Quat, Vec3, quat_mul, quat_normalize
from sitl.sensor_params import MocapParams
from sitl.tick_record import tick_record


@tick_record
class MocapSample:
    """A tracked pose: NED position and q_nb (w, x, y, z)."""

    t_s: float  # capture time
    delivered_t_s: float  # when it becomes available (capture + latency)
    pos_n: Vec3
    q_nb: Quat


class MocapModel:
    """Capture schedule, noise and the delivery queue."""

    def __init__(self, params: MocapParams, rng: np.random.Generator, noise: bool = True) -> None:
        self.params = params
        self.rng = rng
        self.noise = noise
        self.period_s = 1.0 / params.rate_hz
        self.next_capture_t_s = 0.0
        # A second of samples: a reader that stops polling loses the oldest, not memory.
        self._queue: collections.deque[MocapSample] = collections.deque(
            maxlen=max(int(params.rate_hz), 1)
        )
        self._k = 0

    def capture(self, t_s: float, pos_n: Vec3, q_nb: Quat) -> None:
        """Record the pose at t_s and schedule the next capture."""
        prm = self.params
        if self.noise:
            n = self.rng.standard_normal(6).tolist()
            pos_n = (
                pos_n[0] + prm.pos_noise_m * n[0],
                pos_n[1] + prm.pos_noise_m * n[1],
                pos_n[2] + prm.pos_noise_m * n[2],
            )
            h = 0.5 * prm.att_noise_rad
            q_nb = quat_normalize(*quat_mul(q_nb, (1.0, h * n[3], h * n[4], h * n[5])))
        self._queue.append(MocapSample(t_s, t_s + prm.latency_s, pos_n, q_nb))
        self._k += 1
        self.next_capture_t_s = self._k * self.period_s

    def poll(self, t_s: float) -> MocapSample | None:
        """The oldest sample delivered by t_s, else None; call again to drain."""
        if self._queue and self._queue[0].delivered_t_s <= t_s + 1e-12:
            return self._queue.popleft()
        return None
