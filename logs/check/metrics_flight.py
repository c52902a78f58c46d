"""Vibration, control, power, event and hold metrics of a gathered flight (pure)."""

from __future__ import annotations

import itertools
import math
import re

import numpy as np

from logs.check.metrics_link import reference_alt
from logs.check.result import Measured
from logs.check.series import FlightSeries
from logs.check.timeline import flying, held, in_intervals, rms, state_intervals

VIBE_WINDOW_S = 1.0  # vibration is what the accelerometer does about its mean over this long
THROTTLE_BANDS_PCT = (0.0, 25.0, 50.0, 75.0, 100.01)
MIN_BAND_S = 2.0  # a band is judged on this much flying in it, not on a take-off's burst
INTEGRATOR_AT_LIMIT = 0.98  # |I| at this share of its limit or more is "at the limit"
HOVER_SKIP_S = 5.0  # the hover throttle is still being learned this long into a hold
FAILSAFE_MODES = {6: "RTL", 9: "LAND"}  # a change into these nobody asked for is a failsafe
ASKED_WITHIN_S = 10.0  # a mode asked this long before it shows counts as asked
FAILSAFE_STATES = frozenset({"link_lost", "silent"})
_FAILSAFE_TEXT = re.compile(r"failsafe", re.IGNORECASE)
ACK_ACCEPTED = (0, 5)  # MAV_RESULT_ACCEPTED, IN_PROGRESS
HOLD_NEAR_M = 0.1  # a hold is scored once the estimate came this close to its setpoint …
LIPO_CELL_MAX_V = 4.35  # … and cells are counted from the highest voltage seen


def vibration_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """Accelerometer RMS about its moving mean, by axis and by throttle band, in the air."""
    imu = fs.imu
    if len(imu) < 20:
        return {}
    t = imu["t"]
    fly = flying(fs, t)
    if fly.sum() < 20:
        return {}
    rate_hz = (len(t) - 1) / max(float(t[-1] - t[0]), 1e-9)
    n = max(round(rate_hz * VIBE_WINDOW_S), 3)
    kernel = np.ones(n) / n
    out: dict[str, Measured] = {}
    hp = {}
    for axis in ("x", "y", "z"):
        a = imu[f"a{axis}"]
        hp[axis] = a - np.convolve(a, kernel, mode="same")
        out[f"vibration.acc_rms_{axis}_mps2"] = Measured(
            rms(hp[axis][fly]), f"{int(fly.sum())} samples at {rate_hz:.0f} Hz in the air")
    total = np.sqrt(hp["x"] ** 2 + hp["y"] ** 2 + hp["z"] ** 2)
    if len(fs.throttle):
        thr = held(t, fs.throttle["t"], fs.throttle["pct"])
        bands = []
        for lo, hi in itertools.pairwise(THROTTLE_BANDS_PCT):
            sel = fly & (thr >= lo) & (thr < hi)
            if sel.sum() >= max(MIN_BAND_S * rate_hz, 20):
                bands.append((rms(total[sel]), f"{lo:.0f}-{min(hi, 100):.0f} %"))
        if bands:
            value, band = max(bands)
            out["vibration.worst_throttle_band_mps2"] = Measured(
                value, f"worst at throttle {band}; " + ", ".join(
                    f"{b} {v:.2f}" for v, b in bands))
    return out


def control_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """Time at the stick limits, integrator at its limit, hover throttle drift."""
    out: dict[str, Measured] = {}
    c = fs.control
    if len(c):
        # the hold's ticks where the supervisor says so (a take-off climbs at full authority
        # by design); otherwise every tick in the air
        holds = state_intervals(fs, frozenset({"hold"}))
        fly = in_intervals(c["t"], holds) if holds else flying(fs, c["t"])
        n = int(fly.sum())
        if n:
            alt = fs.setup.get("altitude", {})
            lo = float(alt.get("throttle_min_us", 1000))
            hi = float(alt.get("throttle_max_us", 2000))
            thr = c["throttle_us"][fly]
            sat = int(np.sum((thr >= hi - 1) | (thr <= lo + 1)))
            where = "in the hold" if holds else "in the air"
            out["control.stick_limit_pct"] = Measured(
                100.0 * sat / n, f"{sat} of {n} controller ticks {where} at {lo:.0f} or "
                f"{hi:.0f} µs")
            gains = fs.setup.get("altitude", {}).get("gains", {})
            i_max = float(gains.get("i_max", math.nan))
            if math.isfinite(i_max) and i_max > 0:
                at = int(np.sum(np.abs(c["i"][fly]) >= INTEGRATOR_AT_LIMIT * i_max))
                out["control.integrator_limit_pct"] = Measured(
                    100.0 * at / n,
                    f"{at} of {n} ticks with |I| ≥ {INTEGRATOR_AT_LIMIT:g}·{i_max:g}")
        inside = in_intervals(c["t"], [(a + HOVER_SKIP_S, b) for a, b in holds if b - a > 2 *
                                       HOVER_SKIP_S])
        hover = c["hover"][inside & np.isfinite(c["hover"])]
        if hover.size > 10:
            drift = 100.0 * float(np.percentile(hover, 95) - np.percentile(hover, 5))
            out["control.hover_drift_pct"] = Measured(
                drift, f"learned hover {100 * hover.min():.1f}-{100 * hover.max():.1f} % "
                "in the holds")
    elif len(fs.tx_overrides):
        ov = fs.tx_overrides
        fly = flying(fs, ov["t"])
        thr = ov["throttle_us"][fly]
        thr = thr[(thr > 0) & (thr < 65535)]
        if thr.size:
            at = int(np.sum(thr >= 1970))
            out["control.stick_limit_pct"] = Measured(
                100.0 * at / thr.size, f"{at} of {thr.size} overrides in the air at ≥ 1970 µs")
    return out


def power_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """Voltage sag per ampere (fitted with a slow trend for the discharge), lowest cell."""
    b = fs.battery
    if not len(b):
        return {}
    t, v, a = b["t"], b["volt"], b["amp"]
    ok = np.isfinite(v) & (v > 0)
    out: dict[str, Measured] = {}
    if not ok.any():
        return out
    cells = max(1, math.ceil(float(v[ok].max()) / LIPO_CELL_MAX_V))
    fly = flying(fs, t) & ok
    under = v[fly] if fly.any() else v[ok]
    out["power.min_cell_v"] = Measured(float(under.min()) / cells,
                                       f"{float(under.min()):.2f} V over {cells} cells")
    good = ok & np.isfinite(a) & (a >= 0)
    if good.sum() > 10 and float(np.ptp(a[good])) >= 2.0:
        x = np.column_stack([np.ones(good.sum()), a[good], t[good] - t[good][0]])
        coef, *_ = np.linalg.lstsq(x, v[good], rcond=None)
        out["power.sag_v_per_a"] = Measured(
            max(0.0, -float(coef[1])), f"{int(good.sum())} samples, {float(a[good].min()):.1f}-"
            f"{float(a[good].max()):.1f} A")
    return out


def _mode_changes(fs: FlightSeries) -> list[tuple[float, int]]:
    hb = fs.heartbeat
    changes = []
    prev: float | None = None
    for t, mode in zip(hb["t"], hb["mode"], strict=True):
        if prev is not None and mode != prev and math.isfinite(mode):
            changes.append((float(t), int(mode)))
        prev = mode
    return changes


def event_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """Failsafes, modes nobody asked for, refused commands."""
    out: dict[str, Measured] = {}
    failsafes: list[tuple[float, str]] = []
    unasked: list[str] = []
    if len(fs.heartbeat):
        for t, mode in _mode_changes(fs):
            asked = any(m == mode and t - ASKED_WITHIN_S <= ta <= t for ta, m in fs.modes_asked)
            if asked:
                continue
            name = FAILSAFE_MODES.get(mode)
            if name is not None:
                failsafes.append((t, f"{name} at {t:.1f} s unasked"))
            else:
                unasked.append(f"mode {mode} at {t:.1f} s")
        out["events.unasked_modes"] = Measured(float(len(unasked)), "; ".join(unasked[:4]))
    for t, state, reason in fs.states:
        if state in FAILSAFE_STATES:
            failsafes.append((t, f"station {state} at {t:.1f} s ({reason})"))
    for t, source, text in fs.texts:
        if source == "vehicle" and _FAILSAFE_TEXT.search(text):
            failsafes.append((t, f"vehicle said {text!r} at {t:.1f} s"))
    episodes: list[tuple[float, str]] = []
    for t, text in sorted(failsafes):
        if not episodes or t - episodes[-1][0] > ASKED_WITHIN_S:
            episodes.append((t, text))
    if len(fs.heartbeat) or fs.states:
        out["events.failsafes"] = Measured(float(len(episodes)),
                                           "; ".join(e for _t, e in episodes[:3]))
    refused = []
    retried = 0
    for t, cmd, res in fs.acks:
        if res in ACK_ACCEPTED:
            continue
        if any(c2 == cmd and r2 in ACK_ACCEPTED and t2 > t for t2, c2, r2 in fs.acks):
            retried += 1  # refused, then accepted when asked again (arming during boot)
        else:
            refused.append(f"{cmd}→{res} at {t:.1f} s")
    if len(fs.heartbeat):
        out["events.refusals"] = Measured(
            float(len(refused)), "; ".join(refused[:4]) +
            (f" ({retried} refused, then accepted on a retry)" if retried else ""))
    return out


def hold_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """The PC hold's error against its setpoint: RMS, bias, spread, over its longest settled
    stretch of one setpoint; against truth where recorded, else the estimate."""
    c = fs.control
    holds = state_intervals(fs, frozenset({"hold"}))
    if not len(c) or not holds:
        return {}
    settle_s = float(fs.setup.get("flight", {}).get("settle_s", 4.0) or 4.0)
    est = fs.estimate
    est_alt = held(c["t"], est["t"], est["alt"]) if len(est) else np.full(len(c), np.nan)
    best: tuple[float, float] | None = None
    for a, b in holds:
        sel = (c["t"] >= a) & (c["t"] <= b)
        t, sp, alt = c["t"][sel], c["setpoint"][sel], est_alt[sel]
        cuts = np.flatnonzero(np.abs(np.diff(sp)) > 1e-6) + 1
        for seg in np.split(np.arange(t.size), cuts):
            if seg.size < 2:
                continue
            near = np.flatnonzero(np.abs(alt[seg] - sp[seg]) < HOLD_NEAR_M)
            if not near.size:
                continue
            t0 = float(t[seg][near[0]]) + settle_s
            t1 = float(t[seg][-1])
            if t1 - t0 > 1.0 and (best is None or t1 - t0 > best[1] - best[0]):
                best = (t0, t1)
    if best is None:
        return {}
    t0, t1 = best
    ref, source = reference_alt(fs)
    if ref is not None and np.sum((ref[0] >= t0) & (ref[0] <= t1)) > 10:
        t_ref, alt_ref = ref
        sel = (t_ref >= t0) & (t_ref <= t1)
        err = alt_ref[sel] - held(t_ref[sel], c["t"], c["setpoint"])
    else:
        sel = (c["t"] >= t0) & (c["t"] <= t1)
        err = est_alt[sel] - c["setpoint"][sel]
        source = "estimate"
    err = err[np.isfinite(err)]
    if err.size < 10:
        return {}
    mean = float(err.mean())
    note = f"{t1 - t0:.1f} s from {t0:.1f} s, {err.size} {source} samples"
    out = {
        "hold.rms_m": Measured(rms(err), note, source),
        "hold.bias_m": Measured(abs(mean), f"mean {mean:+.3f} m; {note}", source),
        "hold.std_m": Measured(float(err.std()), note, source),
    }
    sel = (c["t"] >= t0) & (c["t"] <= t1) & np.isfinite(c["error"])
    memory = error_memory_s(c["t"][sel], c["error"][sel])
    if math.isfinite(memory):
        out["hold.error_memory_s"] = Measured(
            memory, f"the controller's error (setpoint - estimate) over {t1 - t0:.1f} s",
            "estimate")
    return out


def error_memory_s(t: np.ndarray, e: np.ndarray) -> float:
    """How long an error lasts: the lag at which its autocorrelation first falls below 1/e
    (NaN for too short a record). A stiff hold corrects within a few tenths of a second; a
    soft one (low gains) lets each error linger."""
    if e.size < 40:
        return math.nan
    dt = float(np.median(np.diff(t)))
    x = e - e.mean()
    n = 1 << int(np.ceil(np.log2(2 * x.size)))
    spectrum = np.fft.rfft(x, n)
    ac = np.fft.irfft(spectrum * np.conj(spectrum), n)[: x.size]
    if ac[0] <= 0.0:
        return math.nan
    below = np.flatnonzero(ac / ac[0] < math.exp(-1.0))
    return float(below[0]) * dt if below.size else math.nan
