"""The radiation mapper's mission loop, one for every backend: count, ask, fly through the next.

The mapper is given where the vehicle was while the detector counted (on a vehicle the mean
mocap position, in the kinematic world the sample point itself), and the mission stops when the
vehicle is taken off it (a battery failsafe's LAND, say): a reading from then on is not the
mission's. Nor is one counted away from the mapping height: the field falls off with the
distance to its sources, and a vehicle sinking on a sagging battery before its failsafe acts
(17 cm low at 1 m, lockstep, two 300 mAh packs) would put a reading of another height on the
map. Such a count is dropped and taken again where the vehicle is, a few times in a row at most.
"""

from __future__ import annotations

import math

import numpy as np

from gcs.mission.events import MissionEvent
from gcs.mission.outcome import Outcome
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.port import DetectorPort
from gcs.mission.radiation_maps import finish_radiation, is_reached
from gcs.mission.recording import SAMPLE_RADIATION, radiation_payload
from gcs.mission.report import MissionStatus
from planners.geometry import Vec3
from planners.radiation import RadiationMapper, RadiationMapperParams
from planners.radiation.field import RadiationField

LOOP = "radiation"
TRAVEL_MPS = 0.5  # radiation legs: the timeout grows with the leg at this speed
HEIGHT_TOL_M = 0.15  # a count further than this from the mapping height is not a sample
OFF_HEIGHT_MAX = 5  # counts in a row off the height: the vehicle cannot hold it, stop


def count_time_s(cps: float, p: RadiationMapperParams) -> float:
    """How long the detector will count at a rate like `cps` (whole windows, at most the
    dwell): the next sample's rate is about the last one's."""
    if p.target_counts <= 0.0 or not math.isfinite(cps) or cps <= 0.0:
        return p.dwell_s
    w = p.detector_window_s
    return min(p.dwell_s, w * math.ceil(p.target_counts / (cps * w)))


def fly_radiation(port: DetectorPort, setup: PlannerSetup, start_n: Vec3,
                  truth: RadiationField | None, mapper: RadiationMapper | None = None) -> Outcome:
    """Map the floor from `start_n`; score the map against `truth` when the run may know it
    (else None). A `mapper` given is the one flown (its caller reads its state afterwards),
    else one is made from the setup."""
    spec = port.spec
    v = port.vehicles()[0]
    p = setup.params
    alt = spec.takeoff_alt_m
    if mapper is None:
        mapper = RadiationMapper(p, max_samples=setup.max_samples)
    here = p.clip(np.asarray(start_n[:2], dtype=float))
    target: Vec3 = (float(here[0]), float(here[1]), -alt)
    port.go({v: target}, timeout_s=spec.step_timeout_s + math.dist(start_n, target) / TRAVEL_MPS)
    path: list[Vec3] = [target]
    k = off_height = 0
    stopped: str | None = None
    while True:
        c = port.count(v, p)
        stopped = port.off_mission(v)
        if stopped is not None:
            port.event(MissionEvent.SAMPLE_DROPPED, v, f"sample {k}: {stopped}")
            break
        m, cps = c.at_n, c.counts_per_s
        off_m = -m[2] - alt
        if abs(off_m) > HEIGHT_TOL_M:
            off_height += 1
            port.event(MissionEvent.SAMPLE_DROPPED, v,
                       f"sample {k}: counted {off_m:+.2f} m off the {alt:g} m height")
            if off_height >= OFF_HEIGHT_MAX:
                stopped = f"{off_height} counts in a row off the {alt:g} m height"
                break
            continue
        off_height = 0
        decision = mapper.step((m[0], m[1]), cps, c.counted_s)
        t = port.now_s()
        port.rec.put(SAMPLE_RADIATION, t,
                     {**radiation_payload(k, m, cps, decision), "dwell_s": c.counted_s})
        port.rec.pose(t, m)
        port.say(f"sample {k:4d} at ({m[0]:+6.2f}, {m[1]:+6.2f}) {cps:8.1f} cps "
                 f"{decision.phase.value:11s} {decision.reason}")
        if decision.done or port.over_budget():
            break
        nxt: Vec3 = (float(decision.next_pos_n[0]), float(decision.next_pos_n[1]), -alt)
        leg = math.dist(m, nxt)
        port.fly_to_sample(v, nxt, p, count_time_s(cps, p),
                           spec.step_timeout_s + leg / TRAVEL_MPS)
        path.append(nxt)
        k += 1
    path_xy = np.array([(q[0], q[1]) for q in path])
    metrics, products = finish_radiation(mapper, truth, path_xy, port.rec, port.now_s())
    status, why = is_reached(metrics, setup.min_iou)
    if stopped is not None:
        status, why = MissionStatus.FAILED, f"{stopped} at sample {k}"
    elif port.over_budget() and not mapper.done:
        status, why = MissionStatus.FAILED, f"mission time {spec.max_duration_s:g} s spent"
    return Outcome(status, why, k, path, metrics, (truth, products), loop=LOOP)
