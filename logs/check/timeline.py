"""When the vehicle was armed, flying and holding, read from a gathered flight (pure helpers)."""

from __future__ import annotations

import numpy as np

from logs.check.series import FlightSeries

FLYING_THROTTLE_PCT = 15.0  # VFR_HUD throttle above this, armed: in the air or leaving it
AIRBORNE_STATES = frozenset({"takeoff", "hold", "vehicle", "link_lost", "silent", "quitting"})


def held(t_query: np.ndarray, t: np.ndarray, values: np.ndarray,
         before: float = np.nan) -> np.ndarray:
    """Zero-order hold of (t, values) at the query times (`before` ahead of the first)."""
    if not t.size:
        return np.full(t_query.shape, before)
    i = np.searchsorted(t, t_query, side="right") - 1
    out = values[np.clip(i, 0, None)].astype(float)
    out[i < 0] = before
    return out


def state_intervals(fs: FlightSeries, states: frozenset[str]) -> list[tuple[float, float]]:
    """Intervals the supervisor spent in any of `states` (the last one runs to the end)."""
    out: list[tuple[float, float]] = []
    start: float | None = None
    for t, state, _reason in fs.states:
        if state in states and start is None:
            start = t
        elif state not in states and start is not None:
            out.append((start, t))
            start = None
    if start is not None:
        out.append((start, fs.duration_s))
    return out


def in_intervals(t: np.ndarray, intervals: list[tuple[float, float]]) -> np.ndarray:
    """Which of the times fall inside any interval."""
    mask = np.zeros(t.shape, dtype=bool)
    for a, b in intervals:
        mask |= (t >= a) & (t <= b)
    return mask


def flying(fs: FlightSeries, t: np.ndarray) -> np.ndarray:
    """Which times the vehicle was in the air (the supervisor's word, else armed with throttle
    up, else armed)."""
    if fs.states:
        return in_intervals(t, state_intervals(fs, AIRBORNE_STATES))
    hb = fs.heartbeat
    if not len(hb):
        return np.zeros(t.shape, dtype=bool)
    armed = held(t, hb["t"], hb["armed"], 0.0) > 0.5
    thr = fs.throttle
    if len(thr):
        return armed & (held(t, thr["t"], thr["pct"], 0.0) > FLYING_THROTTLE_PCT)
    return armed


def armed(fs: FlightSeries, t: np.ndarray) -> np.ndarray:
    """Which times the vehicle's heartbeat said armed."""
    hb = fs.heartbeat
    if not len(hb):
        return np.zeros(t.shape, dtype=bool)
    return held(t, hb["t"], hb["armed"], 0.0) > 0.5


def rms(x: np.ndarray) -> float:
    """Root mean square of the finite values (NaN when none)."""
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x * x))) if x.size else float("nan")
