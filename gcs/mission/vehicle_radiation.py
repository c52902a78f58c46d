"""Radiation samples counted on the move by a MAVLink vehicle: where it is sent, and where a
count is attributed (the radiation loop's `fly_to_sample` and `count` on a `TeamPort`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from gcs.mission.craft import Craft
from gcs.mission.port import Count
from gcs.mission.team import Team
from planners.geometry import Vec3
from planners.radiation import RadiationMapperParams

# Radiation samples are counted on the move. Braking to every sample point and waiting there
# until the vehicle was slow spent 2.5 s a sample between counts (1.5 s on the 0.5-1 m legs of
# the fans and the contour), 400 s of a 490 s flight. The set position is put this far past the
# sample point along the leg instead, so the vehicle passes it at speed and the next leg starts
# from there (the floor's edge stops it short).
SAMPLE_THROUGH_M = 0.5
# Counting starts on the approach, half a count's travel before the point so the count is
# centred on it, or once the vehicle has passed its closest approach within this distance.
SAMPLE_PASS_M = 0.6
SAMPLE_PASSED_M = 0.02  # the distance has grown this much since the closest approach
# ... or once it is slower than this within a fraction of the leg: held short of the point
SAMPLE_STILL_MPS = 0.3
SAMPLE_REACH_FRACTION = 0.6
SAMPLE_SPEED_WINDOW_S = 0.25
SAMPLE_POLL_S = 0.05  # station time: the same sampling however fast the SITL runs


def _flying() -> bool:
    return False


def fly_to_sample(f: Team, craft: Craft, target: Vec3, p: RadiationMapperParams,
                   count_s: float, timeout_s: float, off: Callable[[], bool] = _flying) -> bool:
    """Fly through `target` until counting there should start; False on timeout, or as soon
    as `off` says the vehicle left the mission (a failsafe's LAND): the loop then says why.

    A reading is attributed to where the vehicle was while counting (see `count_on_the_move`),
    so it need not stop at the set position: the mapper is told where each sample was taken.
    Counting over a path of length L and attributing it to the path's mean position errs by
    about L²/24 of the field's relative curvature (<= 2/m² at 1 m height): 2 % for a 0.5 m
    count, less than the counting noise.
    """
    here = craft.position_n()
    leg = np.subtract(target[:2], here[:2])
    norm = float(np.linalg.norm(leg))
    short_m = max(f.spec.position_tolerance_m, SAMPLE_REACH_FRACTION * norm)
    ahead = target[:2] + (SAMPLE_THROUGH_M / norm) * leg if norm > 1e-6 else np.asarray(target[:2])
    past = p.clip(ahead)
    craft.command((float(past[0]), float(past[1]), target[2]))
    start = f.clock.now_s()
    seen: list[tuple[float, Vec3]] = []
    closest = math.inf
    while True:
        now = f.clock.now_s()
        craft.refresh()
        here = craft.position_n()
        # speed over a few polls: motion capture poses reach the station in bursts
        seen = [(t, q) for t, q in seen if now - t <= SAMPLE_SPEED_WINDOW_S] + [(now, here)]
        t_old, q_old = seen[0]
        speed = math.dist(here[:2], q_old[:2]) / (now - t_old) if now > t_old else math.inf
        dist = math.dist(here[:2], target[:2])
        closest = min(closest, dist)
        reach = max(f.spec.position_tolerance_m,
                    0.5 * speed * count_s if math.isfinite(speed) else 0.0)
        if (dist <= reach or (closest <= SAMPLE_PASS_M and dist > closest + SAMPLE_PASSED_M)
                or (dist <= short_m and speed <= SAMPLE_STILL_MPS)):
            return True
        if now - start >= timeout_s or off():
            return False
        f.clock.sleep_until(now + SAMPLE_POLL_S)


def count_on_the_move(f: Team, craft: Craft, p: RadiationMapperParams,
                      off: Callable[[], bool] = _flying) -> Count:
    """Integrate the detector from now: mean counts/s, seconds counted, where it counted.

    Counting stops at `p.dwell_s`, once `off` says the vehicle left the mission, or once
    `p.target_counts` are in (the detector reports counts/s over windows of
    `p.detector_window_s`). The vehicle may be moving: each report is
    attributed to the mean motion-capture position over its own window, and the reading to the
    mean of those, not to one look at the end (near a source the rate changes by several per
    cent per centimetre).
    """
    t0 = f.clock.now_s()
    end = t0 + p.dwell_s
    seen: list[Vec3] = []
    got: list[float] = []
    while f.clock.now_s() < end:
        seen.append(craft.position_n())
        got = [r.counts_per_s for r in craft.radiation_since(t0)]
        if got and p.target_counts > 0.0 and sum(got) * p.detector_window_s >= p.target_counts:
            break
        if off():
            break  # what it counted from here on would be the LAND's, or the floor's
        f.clock.sleep_until(f.clock.now_s() + SAMPLE_POLL_S)
    seen.append(craft.position_n())
    reports = craft.radiation_since(t0)
    got = [r.counts_per_s for r in reports]
    cps = float(np.mean(got)) if got else math.nan
    # a report stamped just after t0 counted over a window that began before it
    trail = craft.mocap_since(t0 - p.detector_window_s)
    means = [np.mean(np.array(w), axis=0) for r in reports
             if (w := [q for t, q in trail if r.t_s - p.detector_window_s < t <= r.t_s])]
    mean = np.mean(np.array(means if means else seen), axis=0)
    counted_s = len(got) * p.detector_window_s if got else p.dwell_s
    return Count(cps, counted_s, (float(mean[0]), float(mean[1]), float(mean[2])))
