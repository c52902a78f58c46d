"""The safety properties a fault search checks, each a margin on a run's trace (`Trace`): how far
the run stayed from violating it, negative when it did. A property with nothing to judge in a
run (no kill, no loss) gives None. The table in docs/fault-search.md says where each comes from.

Margins are in the property's own unit (m, m/s, s); the two yes-or-no properties give +1 or -1.
A search minimises the smallest, so a property that is nearly violated draws it closer.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable
from dataclasses import dataclass

from lab.faultsearch.trace import Trace, TruthSample

OVERSHOOT_M = 0.3  # DESIGN/issue: never above the hold's setpoint + 0.3 m outside a climb
IMPACT_MPS = 1.0  # never into the floor or a box faster than this
ESTIMATE_BOUND_M = 0.3  # the estimate within this of the truth while the sensors are healthy
HEALTHY_AFTER_S = 3.0  # ... and this long after the last sensor, link or stall fault ended
SONAR_FLOOR_M = 0.4  # below it the sonar nears its minimum range: the estimate may coast
KILL_DISARM_S = 1.0  # kill: disarmed within this of a working uplink
RESUME_RISE_M = 0.2  # after a loss brought it down, the vehicle never rises this much again
# docs/safety.md's link-loss table: LAND after 1.5 s of silence, the vehicle's failsafe 5 s after
# the last override if the uplink is dead, LAND's 4 s pause, its descent at 0.5 m/s, 3 s to disarm
LAND_DEADLINE_S = 1.5 + 5.0 + 4.0 + 3.0 + 3.0
LAND_SPEED_MPS = 0.5
PC_STATES = frozenset({"spool_up", "takeoff", "hold"})
FAULT_KINDS_UNHEALTHY = ("fade", "loss", "bitflip", "stall", "sonar", "imu", "battery")


@dataclass(frozen=True, slots=True)
class Margin:
    """One property's margin in one run, where it was smallest and why."""

    name: str
    margin: float
    t_s: float
    note: str = ""


def _alt_at(trace: Trace) -> Callable[[float], TruthSample | None]:
    times = [s.t_s for s in trace.truth]

    def at(t_s: float) -> TruthSample | None:
        i = bisect.bisect_right(times, t_s) - 1
        return trace.truth[i] if i >= 0 else None
    return at


def overshoot(trace: Trace) -> Margin | None:
    """Never above the highest setpoint commanded so far + 0.3 m (a climb to a new setpoint
    raises the ceiling at once, so only the climb's overshoot counts)."""
    sts = trace.station
    j, ceiling = 0, None
    best: Margin | None = None
    for s in trace.truth:
        while j < len(sts) and sts[j].t_s <= s.t_s:
            sp = sts[j].setpoint_m
            if sp is not None:
                ceiling = sp if ceiling is None else max(ceiling, sp)
            j += 1
        if ceiling is None or s.on_ground:
            continue
        m = ceiling + OVERSHOOT_M - s.alt_m
        if best is None or m < best.margin:
            best = Margin("overshoot", m, s.t_s, f"{s.alt_m:.2f} m with setpoint {ceiling:.2f} m")
    return best


def impact(trace: Trace) -> Margin | None:
    """Never onto the floor or a box faster than 1.0 m/s: the sink speed as contact begins
    (until the pilot's kill: a killed vehicle falls, as the pilot asked)."""
    best: Margin | None = None
    prev: TruthSample | None = None
    kills = trace.event_times("pilot_kill")
    stop = min(kills) if kills else float("inf")
    for s in trace.truth:
        if s.t_s >= stop:
            break
        if prev is not None and ((s.on_ground and not prev.on_ground)
                                 or (s.touching and not prev.touching)):
            speed = max(prev.vz_down_mps, 0.0)
            m = IMPACT_MPS - speed
            if best is None or m < best.margin:
                what = s.touching or "the floor"
                best = Margin("impact", m, s.t_s, f"onto {what} at {speed:.2f} m/s")
        prev = s
    return best


def _causes(trace: Trace) -> list[tuple[float, str]]:
    causes = [(t, k) for t, k in trace.events if k in ("pilot_quit", "pilot_land", "mode_land")]
    lost = next((s.t_s for s in trace.station if s.link_lost), None)
    if lost is not None:
        causes.append((lost, "link lost"))
    if trace.flight_end_s > 0.0:
        causes.append((trace.flight_end_s, "fly ended"))
    return sorted(causes)


def landed(trace: Trace) -> Margin | None:
    """On the floor and disarmed within the documented time of a landing cause (a quit, a
    LAND, the vehicle's own LAND, a lost link, the flight's end)."""
    at = _alt_at(trace)
    best: Margin | None = None
    for t_c, why in _causes(trace):
        s = at(t_c)
        if s is None:
            continue
        deadline = t_c + LAND_DEADLINE_S + max(s.alt_m, 0.0) / LAND_SPEED_MPS
        down = next((u.t_s for u in trace.truth
                     if u.t_s >= t_c and u.on_ground and not u.armed), None)
        end = trace.truth[-1].t_s
        if down is None and end < deadline:
            continue  # the run ended before the deadline: nothing to judge
        m = deadline - (down if down is not None else end)
        if best is None or m < best.margin:
            note = (f"{why} at {t_c:.1f} s: " + (f"down and disarmed at {down:.1f} s"
                                                  if down is not None else "never disarmed"))
            best = Margin("landed", m, t_c, note)
    return best


def box_contact(trace: Trace) -> Margin | None:
    """No contact with a world's boxes: the closest the body came to one (None: no boxes)."""
    if not trace.boxes:
        return None
    best: Margin | None = None
    for s in trace.truth:
        n, e = s.pos_ne
        z = -s.alt_m
        for b in trace.boxes:
            dn = max(b.min_n[0] - n, 0.0, n - b.max_n[0])
            de = max(b.min_n[1] - e, 0.0, e - b.max_n[1])
            dz = max(b.min_n[2] - z, 0.0, z - b.max_n[2])
            d = (dn * dn + de * de + dz * dz) ** 0.5 - trace.body_radius_m
            m = -0.01 if s.touching == b.name else d
            if best is None or m < best.margin:
                best = Margin("box_contact", m, s.t_s, f"box {b.name}")
    return best


def _unhealthy_until(trace: Trace, plan_faults: list[tuple[float, float, str]]) -> list[
        tuple[float, float]]:
    return [(b, b + length + HEALTHY_AFTER_S) for b, length, kind in plan_faults
            if kind.startswith(FAULT_KINDS_UNHEALTHY)]


def estimate(trace: Trace, faults: list[tuple[float, float, str]]) -> Margin | None:
    """The estimate within 0.3 m of the truth while the sensors are healthy: from the hold to
    the landing, over the sonar's floor (0.4 m), no sensor, link or stall fault in the last
    3 s, before any kill."""
    at = _alt_at(trace)
    sick = _unhealthy_until(trace, faults)
    kills = trace.event_times("pilot_kill")
    stop = min([*kills, trace.anchors.get("landing", float("inf")),
                trace.flight_end_s or float("inf")])
    start = trace.anchors.get("hold")
    if start is None:
        return None
    best: Margin | None = None
    for s in trace.station:
        if s.est_alt_m is None or s.t_s < start or s.t_s > stop or s.link_lost:
            continue
        if any(a <= s.t_s < b for a, b in sick):
            continue
        u = at(s.t_s)
        if u is None or u.on_ground or u.alt_m < SONAR_FLOOR_M:
            continue
        err = abs(s.est_alt_m - u.alt_m)
        m = ESTIMATE_BOUND_M - err
        if best is None or m < best.margin:
            best = Margin("estimate", m, s.t_s, f"estimate {s.est_alt_m:.2f} m, truth "
                          f"{u.alt_m:.2f} m")
    return best


def kill(trace: Trace, uplink_dead: list[tuple[float, float]]) -> Margin | None:
    """Kill: throttle minimum on the station's next tick, disarmed within 1 s of a working
    uplink."""
    best: Margin | None = None
    for t_k in trace.event_times("pilot_kill"):
        nxt = next((s for s in trace.station if s.t_s > t_k), None)
        if nxt is not None and nxt.throttle_us > trace.throttle_min_us:
            m = -0.01 - (nxt.throttle_us - trace.throttle_min_us) / 1000.0
            return Margin("kill", m, nxt.t_s, f"throttle {nxt.throttle_us} us a tick after kill")
        works = t_k
        for a, b in sorted(uplink_dead):
            if a <= works < b:
                works = b
        deadline = works + KILL_DISARM_S
        off = next((u.t_s for u in trace.truth if u.t_s >= t_k and not u.armed), None)
        end = trace.truth[-1].t_s if trace.truth else t_k
        if off is None and end < deadline:
            continue
        m = deadline - (off if off is not None else end)
        if best is None or m < best.margin:
            best = Margin("kill", m, t_k, "never disarmed" if off is None
                          else f"disarmed {off - t_k:.2f} s after the kill")
    return best


def no_resume(trace: Trace) -> Margin | None:
    """Nothing resumes by itself after a loss: no PC control again, no re-arming, no rise of
    0.2 m once the vehicle is down."""
    lost = next((s.t_s for s in trace.station if s.link_lost), None)
    if lost is None:
        return None
    back = next((s for s in trace.station if s.t_s > lost and s.state in PC_STATES), None)
    if back is not None:
        return Margin("no_resume", -1.0, back.t_s, f"station back in {back.state} after the loss")
    down: TruthSample | None = None
    rise = 0.0
    for u in trace.truth:
        if u.t_s < lost:
            continue
        if down is None:
            if u.on_ground and not u.armed:
                down = u
            continue
        if u.armed:
            return Margin("no_resume", -1.0, u.t_s, "re-armed after the loss")
        rise = max(rise, u.alt_m - down.alt_m)
    return Margin("no_resume", RESUME_RISE_M - rise, lost, f"rose {rise:.2f} m after landing")


def exit_honest(trace: Trace, others: list[Margin], faults_begun: int) -> Margin:
    """`fly` exits zero only when the flight went as commanded, non-zero whenever a property
    failed or the pilot or the vehicle broke the flight off; a failure with no fault is a lie
    too."""
    broke_off = any(k in ("pilot_kill", "pilot_quit", "pilot_land", "mode_land")
                    and t <= trace.flight_end_s for t, k in trace.events)
    violated = [m.name for m in others if m.margin < 0.0]
    if trace.exit_ok and (violated or broke_off):
        why = ", ".join(violated) or "the flight was broken off"
        return Margin("exit_honest", -1.0, trace.flight_end_s, f"exit 0 though {why}")
    if not trace.exit_ok and not violated and faults_begun == 0:
        return Margin("exit_honest", -1.0, trace.flight_end_s,
                      f"failed with no fault: {trace.exit_reason}")
    return Margin("exit_honest", 1.0, trace.flight_end_s,
                  "ok" if trace.exit_ok else trace.exit_reason[:80])


PROPERTIES = ("overshoot", "impact", "landed", "box_contact", "estimate", "kill", "no_resume",
              "exit_honest")


def evaluate(trace: Trace, faults: list[tuple[float, float, str]],
             names: tuple[str, ...] = PROPERTIES) -> list[Margin]:
    """Every asked property's margin (those with something to judge). `faults`: (begin,
    length, kind) of each fault that began."""
    dead = [(b, b + n) for b, n, k in faults if k in ("fade_up", "fade_both", "stall")]
    found = [overshoot(trace), impact(trace), landed(trace), box_contact(trace),
             estimate(trace, faults), kill(trace, dead), no_resume(trace)]
    margins = [m for m in found if m is not None and m.name in names]
    if "exit_honest" in names:
        margins.append(exit_honest(trace, margins, len(faults)))
    return margins
