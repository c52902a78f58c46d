"""How hard the hold may push a vehicle down that might have to fly its command blind.

An autopilot whose uplink dies flies the last override it got until its own failsafe acts:
ArduCopter 3.2.1's radio failsafe 2 s after the last override, 4.x's GCS failsafe after
FS_GCS_TIMEOUT (under RC_OVERRIDE_TIME, 3 s by default). The station cannot know which command
will be the last, so every command in a hold is one the vehicle may fly alone for those
seconds, and then the firmware's LAND takes over and brakes. A command asking a downward
acceleration a (below the learned hover) from a height h while climbing at w meets the floor
within those seconds at √(w² + 2·a·h), or is braked by the firmware from where it got to; the
largest a whose touchdown stays at the bound is the hold's limit. A steady 1 m hold may then ask
about 0.3 m/s² down (the hold's throttle noise, the estimate's velocity through the D term,
reaches ±0.6 m/s²): that clipped noise is the price.

Only a steady hold is bounded so. A vehicle the hold must stop (climbing past a carpet's late
echoes, say) needs braking that, held blind, would put it into the floor: bounding it there
throws the vehicle at the ceiling instead, which the station cannot see. So a climb gets the
braking that stops it `band_m` above the setpoint, `brake_factor` times over (the vehicle answers
late), and a fade in those moments is as unbounded as it ever was; climbs are never bounded.
The climb is the estimate's, whose velocity in a steady hold wanders to 0.15–0.2 m/s while the
vehicle's stays under 0.13 m/s: braked by speed alone, that noise opened the bound to the PID's.
For that wander, near the setpoint, the braking a climb gets is a few tenths of a m/s², at or
under the steady bound.
A profile's own planned braking (a take-off's end) passes below the bound
(gcs/control/pid.py). A sink past `steady_mps` opens the bound as before, by twice it to
the PID's limit: bounding those moments put a lossy-link hold 0.106 m off its setpoint
(1 of 60 seeds, apm25).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

_MIN_ROOM_M = 0.01  # at the band or past it, a climb is braked as if 1 cm short of it
_SEARCH_STEPS = 12  # bisection over [0, max_mps2]: 6 m/s² / 4096 ≈ 1.5 mm/s², ample


@dataclass(frozen=True, slots=True)
class BlindFlight:
    """What a vehicle left alone does, and what it may do."""

    blind_s: float  # the last command flown this long before the firmware acts
    brake_mps2: float  # then the firmware's LAND brakes a descent at least this hard
    touchdown_mps: float  # the fastest it may meet the floor
    max_mps2: float  # the most the hold ever asks (the PID's own limit)
    steady_mps: float  # a sink faster than this opens the bound, by twice it to the PID's
    band_m: float  # a climb is stopped within this above the setpoint
    brake_factor: float  # that many times the braking that just stops it there


def blind_touchdown(height_m: float, climb_mps: float, sink_mps2: float,
                    blind: BlindFlight) -> float:
    """The speed at which a vehicle `height_m` above the surface below, climbing at `climb_mps`,
    meets that surface when it flies `sink_mps2` (≥ 0, downward) blind (0: braked above it)."""
    h, w, a, t = height_m, climb_mps, sink_mps2, blind.blind_s
    if h <= 0.0:
        return max(-w, 0.0)
    if a > 0.0:
        t_hit = (w + math.sqrt(w * w + 2.0 * a * h)) / a
    elif w < 0.0:
        t_hit = h / -w
    else:
        return 0.0  # level or climbing, nothing pulling down: the firmware's LAND brings it
    if t_hit <= t:
        return math.sqrt(w * w + 2.0 * a * h)
    w_t = w - a * t
    if w_t >= 0.0:
        return 0.0
    z_t = h + w * t - 0.5 * a * t * t
    return math.sqrt(max(w_t * w_t - 2.0 * blind.brake_mps2 * z_t, 0.0))


def blind_sink_limit(height_m: float, climb_mps: float, above_m: float,
                     blind: BlindFlight) -> float:
    """The most downward acceleration (m/s², ≥ 0, below hover) a command may ask so that flown
    blind it meets the floor no faster than `blind.touchdown_mps`, or the braking that stops a
    climb of `climb_mps` from `above_m` over the setpoint in time; inf when even the PID's limit
    does. Never below 0: a sink already that fast is the hold's to brake, and an envelope that
    demanded a climb would turn a wrong estimate (a carpet's late echo) into one."""
    if not math.isfinite(blind.touchdown_mps):
        return math.inf
    limit = _blind_limit(height_m, climb_mps, blind)
    if not math.isfinite(limit):
        return limit
    if climb_mps > 0.0:
        room = max(blind.band_m - above_m, _MIN_ROOM_M)
        need = blind.brake_factor * climb_mps * climb_mps / (2.0 * room)
        return math.inf if need >= blind.max_mps2 else max(limit, need)
    opening = (-climb_mps - blind.steady_mps) / blind.steady_mps
    if opening <= 0.0:
        return limit
    return math.inf if opening >= 1.0 else limit + opening * (blind.max_mps2 - limit)


def _blind_limit(height_m: float, climb_mps: float, blind: BlindFlight) -> float:
    v, max_mps2 = blind.touchdown_mps, blind.max_mps2
    h, w = height_m, climb_mps
    if h > 0.0 and w * w < v * v:
        # A steady hold's case in closed form: the limit of a fall that meets the floor
        # within blind_s is where √(w² + 2·a·h) = v, which it then does after (w + v)/a; a
        # larger a only meets it sooner
        a = (v * v - w * w) / (2.0 * h)
        if a < max_mps2 and (w + v) / a <= blind.blind_s:
            return a
    if blind_touchdown(height_m, climb_mps, max_mps2, blind) <= v:
        return math.inf
    lo, hi = 0.0, max_mps2
    if blind_touchdown(height_m, climb_mps, lo, blind) > v:
        return 0.0
    for _ in range(_SEARCH_STEPS):
        mid = 0.5 * (lo + hi)
        if blind_touchdown(height_m, climb_mps, mid, blind) <= v:
            lo = mid
        else:
            hi = mid
    return lo
