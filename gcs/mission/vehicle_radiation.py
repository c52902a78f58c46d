"""The radiation mapper flown on a vehicle: hold near a sample point, count, ask for the next.

The mapper is given where the vehicle was while the detector counted (the mean mocap position),
and its mission stops when the autopilot takes the vehicle over (a battery failsafe's LAND, say).
"""

from __future__ import annotations

import math

import numpy as np

from gcs.mission.craft import Craft
from gcs.mission.events import MissionEvent
from gcs.mission.off_mission import off_mission
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.radiation_maps import finish_radiation, is_reached
from gcs.mission.recording import SAMPLE_RADIATION, radiation_payload
from gcs.mission.report import MissionStatus
from gcs.mission.team import Team
from gcs.mission.vehicle_planners import Outcome
from planners.geometry import Vec3
from planners.radiation import RadiationMapper, RadiationMapperParams
from planners.radiation_field import RadiationField

TRAVEL_MPS = 0.5  # radiation legs: the timeout grows with the leg at this speed
# Radiation: count once slower than this (mocap, over a quarter second) and within a fraction
# of the leg (or the tolerance) of the set position. The position hold overshoots a short leg
# by about half its length and rings for seconds; counting starts at the first turning point.
# Counting over a path of length L and attributing the reading to its mean position errs by
# about L²/24 of the field's relative curvature (<= 2/m² at 1 m height): under 1 % at these
# speeds, less than the counting noise.
SAMPLE_STILL_MPS = 0.3
SAMPLE_REACH_FRACTION = 0.6
SAMPLE_SPEED_WINDOW_S = 0.25
SAMPLE_POLL_S = 0.05  # station time: the same sampling however fast the SITL runs


def _hold_for_sample(f: Team, craft: Craft, target: Vec3, leg_m: float,
                     timeout_s: float) -> bool:
    """Fly to `target` until the vehicle is near it and nearly still; False on timeout.

    A radiation reading is attributed to where the vehicle was while counting (see `_dwell`),
    so it need not be exactly at the set position: near it and slow is as good a sample, and
    the mapper is told where it was taken. Waiting instead for the position hold's ringing to
    die down within centimetres of every set position spent the battery before the map was
    done (7.4 s a sample; now about 4).
    """
    reach_m = max(f.spec.position_tolerance_m, SAMPLE_REACH_FRACTION * leg_m)
    craft.command(target)
    start = f.clock.now_s()
    seen: list[tuple[float, Vec3]] = []
    still_since: float | None = None
    while True:
        now = f.clock.now_s()
        craft.refresh()
        here = craft.position_n()
        # speed over a few polls: motion capture poses reach the station in bursts
        seen = [(t, q) for t, q in seen if now - t <= SAMPLE_SPEED_WINDOW_S] + [(now, here)]
        t_old, q_old = seen[0]
        speed = math.dist(here[:2], q_old[:2]) / (now - t_old) if now > t_old else math.inf
        if math.dist(here, target) <= reach_m and speed <= SAMPLE_STILL_MPS:
            still_since = now if still_since is None else still_since
            if now - still_since >= f.spec.settle_s:
                return True
        else:
            still_since = None
        if now - start >= timeout_s:
            return False
        f.clock.sleep_until(now + SAMPLE_POLL_S)


def _dwell(f: Team, craft: Craft, p: RadiationMapperParams) -> tuple[float, float, Vec3]:
    """Integrate the detector while holding: (mean counts/s, seconds counted, mean mocap
    position over the dwell).

    Counting stops at `p.dwell_s`, or once `p.target_counts` are in (the detector reports
    counts/s over windows of `p.detector_window_s`). The reading is attributed to where the
    vehicle was while counting, not to one look at the end: position hold wanders by
    centimetres, and near a source the rate changes by several per cent per centimetre.
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
        f.clock.sleep_until(f.clock.now_s() + SAMPLE_POLL_S)
    seen.append(craft.position_n())
    got = [r.counts_per_s for r in craft.radiation_since(t0)]
    cps = float(np.mean(got)) if got else math.nan
    mean = np.mean(np.array(seen), axis=0)
    counted_s = len(got) * p.detector_window_s if got else p.dwell_s
    return cps, counted_s, (float(mean[0]), float(mean[1]), float(mean[2]))


def fly_radiation(f: Team, setup: PlannerSetup, hover: dict[int, Vec3],
               truth: RadiationField | None) -> Outcome:
    """Map the floor; score the map against `truth` when the run may know it (else None)."""
    spec = f.spec
    v = next(iter(f.crafts))
    craft = f.crafts[v]
    p = setup.params
    alt = spec.takeoff_alt_m
    mapper = RadiationMapper(p, max_samples=setup.max_samples)
    here = p.clip(np.asarray(hover[v][:2], dtype=float))
    target: Vec3 = (float(here[0]), float(here[1]), -alt)
    f.go({v: target}, timeout_s=spec.step_timeout_s + math.dist(hover[v], target) / TRAVEL_MPS)
    path: list[Vec3] = [target]
    k = 0
    stopped: str | None = None
    while True:
        cps, counted_s, m = _dwell(f, craft, p)
        stopped = off_mission(craft.snapshot(), f.elapsed_s())
        if stopped is not None:
            f.event(MissionEvent.SAMPLE_DROPPED, v, f"sample {k}: {stopped}")
            break
        decision = mapper.step((m[0], m[1]), cps, counted_s)
        t = f.clock.now_s()
        f.rec.put(SAMPLE_RADIATION, t,
                  {**radiation_payload(k, m, cps, decision), "dwell_s": counted_s})
        f.rec.pose(t, m)
        f.say(f"sample {k:4d} at ({m[0]:+6.2f}, {m[1]:+6.2f}) {cps:8.1f} cps "
              f"{decision.phase.value:11s} {decision.reason}")
        if decision.done or f.over_budget():
            break
        nxt: Vec3 = (float(decision.next_pos_n[0]), float(decision.next_pos_n[1]), -alt)
        leg = math.dist(m, nxt)
        _hold_for_sample(f, craft, nxt, leg, spec.step_timeout_s + leg / TRAVEL_MPS)
        path.append(nxt)
        k += 1
    path_xy = np.array([(q[0], q[1]) for q in path])
    metrics, products = finish_radiation(mapper, truth, path_xy, f.rec, f.clock.now_s())
    status, why = is_reached(metrics, setup.min_iou)
    if stopped is not None:
        status, why = MissionStatus.FAILED, f"{stopped} at sample {k}"
    elif f.over_budget() and not mapper.done:
        status, why = MissionStatus.FAILED, f"mission time {spec.max_duration_s:g} s spent"
    return Outcome(status, why, k, path, metrics, (truth, products))
