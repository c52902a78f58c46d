"""The vehicle-to-station clock offset the catch-up places late samples by: the least delay of
the last `offset_window_s`, kept as a rising deque instead of a scan of the window."""

from __future__ import annotations

import numpy as np

from firmware_link.records import Imu
from gcs.estimation.catch_up import CatchUp, CatchUpParams, EstimatorTick

TICK_S = 0.025


class _Still:
    """An estimator with nothing to keep: the offset is all that is looked at."""

    def snapshot(self) -> object:
        return None

    def restore(self, state: object) -> None:
        pass


def _tick(t_s: float, delay_s: float) -> EstimatorTick:
    sample_t = t_s - delay_s
    imu = Imu(t_s, 1, (0.0, 0.0, -9.81), (0.0, 0.0, 0.0), "RAW_IMU", round(sample_t * 1e6))
    return EstimatorTick(t_s, (imu,), (), None, False, None)


def test_the_offset_is_the_least_delay_of_the_window_as_it_slides() -> None:
    rng = np.random.default_rng(7)
    params = CatchUpParams()
    catch_up = CatchUp(params)
    seen: list[tuple[float, float]] = []
    # delays that fall and rise in runs, so the least leaves the window while larger ones stay
    delays = 0.02 + 0.08 * np.abs(np.sin(np.arange(800) / 37.0)) + rng.uniform(0, 0.01, 800)
    for k, delay in enumerate(delays):
        t = 1.0 + k * TICK_S
        inputs = _tick(t, float(delay))
        catch_up.tick(_Still(), inputs, lambda _: None)
        imu = inputs.imus[-1]
        seen.append((t, imu.t_s - imu.time_usec * 1e-6))
        window = [o for tt, o in seen if tt >= t - params.offset_window_s]
        assert catch_up._offset_s() == min(window)
