"""Link, loop and estimator metrics of a gathered flight (pure)."""

from __future__ import annotations

import math

import numpy as np

from logs.check.result import Measured
from logs.check.series import FlightSeries
from logs.check.timeline import flying, held, rms

GAP_S = 0.3  # a silence longer than this is a gap
RATE_SETTLE_S = 2.0  # after a rate is asked, the vehicle's scheduler takes this long to follow
# ArduCopter's data streams (REQUEST_DATA_STREAM ids) and one message each always carries
STREAM_MESSAGE = {1: "RAW_IMU", 2: "SYS_STATUS", 3: "SERVO_OUTPUT_RAW", 6: "GLOBAL_POSITION_INT",
                  10: "ATTITUDE", 11: "VFR_HUD", 12: "AHRS"}


def link_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """Loss by sequence numbers, silences, and delivered against asked stream rates."""
    out: dict[str, Measured] = {}
    if not fs.rx_frames:
        return out
    got = lost = 0
    for frames in fs.rx_frames.values():
        seqs = np.array([s for _t, s in frames], dtype=int)
        got += seqs.size
        lost += int(np.sum((np.diff(seqs) - 1) % 256)) if seqs.size > 1 else 0
    out["link.loss_pct"] = Measured(100.0 * lost / max(got + lost, 1),
                                    f"{lost} lost of {got + lost} frames (sequence gaps)")
    t = np.sort(np.asarray(fs.rx_times))
    # before any stream is asked for a vehicle sends only heartbeats, and a team's stations
    # come up one after the other: silences that matter are those of an armed vehicle
    start = min((a for a, _w, _r in fs.rates_asked), default=t[0]) + RATE_SETTLE_S
    end = t[-1]
    span = armed_span(fs)
    if span is not None:
        start, end = max(start, span[0]), span[1]
    t = t[(t >= start) & (t <= end)]
    if t.size > 1:
        d = np.diff(t)
        big = d > GAP_S
        out["link.gaps"] = Measured(float(big.sum()), f"silences over {GAP_S:g} s from "
                                    f"{start:.1f} s to {end:.1f} s")
        i = int(np.argmax(d))
        out["link.longest_silence_s"] = Measured(float(d[i]), f"at {t[i]:.1f} s")
    rate = _stream_rates(fs)
    if rate is not None:
        out["link.stream_rate_pct"] = rate
    return out


def armed_span(fs: FlightSeries) -> tuple[float, float] | None:
    """From the first heartbeat that says armed to the first disarmed one after the last armed
    one (or the end), None if never armed."""
    hb = fs.heartbeat
    if not len(hb):
        return None
    armed = np.flatnonzero(hb["armed"] > 0.5)
    if not armed.size:
        return None
    last = int(armed[-1])
    end = float(hb["t"][last + 1]) if last + 1 < len(hb) else fs.duration_s
    return float(hb["t"][armed[0]]), end


def _stream_rates(fs: FlightSeries) -> Measured | None:
    last: dict[str, tuple[float, float]] = {}
    for t_asked, what, hz in fs.rates_asked:
        last[what] = (t_asked, hz)
    if not last or not fs.rx_times:
        return None
    end = max(fs.rx_times)
    worst: tuple[float, str] | None = None
    notes = []
    for what, (t_asked, hz) in sorted(last.items()):
        kind, _, name = what.partition(":")
        msg = STREAM_MESSAGE.get(int(name)) if kind == "stream" and name.isdigit() else name
        if hz <= 0 or msg is None or msg not in fs.rx_types:
            continue
        t0 = t_asked + RATE_SETTLE_S
        if end - t0 < 5.0:
            continue
        stamps = np.asarray(fs.rx_types[msg])
        delivered = float(np.sum(stamps >= t0)) / (end - t0)
        pct = 100.0 * delivered / hz
        notes.append(f"{msg} {delivered:.1f}/{hz:g} Hz")
        if worst is None or pct < worst[0]:
            worst = (pct, msg)
    if worst is None:
        return None
    return Measured(worst[0], f"worst {worst[1]}; " + ", ".join(notes))


def loop_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """The PC loop's own timing, as it recorded each tick."""
    lp = fs.loop
    if not len(lp):
        return {}
    n = len(lp)
    jitter = lp["jitter_ms"][np.isfinite(lp["jitter_ms"])]
    late_ms = 0.5 * fs.period_s * 1e3
    late = int(np.sum(lp["lateness_ms"] > late_ms))
    overruns = int(np.sum(lp["overrun"] > 0.5))
    return {
        "loop.jitter_p99_ms": Measured(float(np.percentile(jitter, 99)) if jitter.size
                                       else math.nan, f"{n} ticks"),
        "loop.overruns_pct": Measured(100.0 * overruns / n, f"{overruns} of {n} ticks"),
        "loop.late_ticks_pct": Measured(100.0 * late / n,
                                        f"{late} of {n} ticks woke over {late_ms:g} ms late"),
    }


def estimator_metrics(fs: FlightSeries) -> dict[str, Measured]:
    """Innovations, gate rejections, and the estimate against truth or motion capture."""
    est = fs.estimate
    if not len(est):
        return {}
    out: dict[str, Measured] = {}
    used = est["used"] > 0.5
    inn = est["innovation"][used]
    if inn.size:
        out["estimator.innovation_rms_m"] = Measured(
            rms(inn), f"{inn.size} sonar updates, mean {np.nanmean(inn):+.3f} m")
    rejected = est["rejected"][np.isfinite(est["rejected"])]
    if rejected.size:
        n_rej = float(rejected[-1] - rejected[0])
        out["estimator.rejected_pct"] = Measured(
            100.0 * n_rej / max(n_rej + float(used.sum()), 1.0),
            f"{n_rej:.0f} rejected, {int(used.sum())} used")
    ref, source = reference_alt(fs)
    if ref is not None:
        t_ref, alt_ref = ref
        fly = flying(fs, t_ref)
        alt_est = held(t_ref, est["t"], est["alt"])
        err = (alt_est - alt_ref)[fly]
        if np.isfinite(err).sum() > 10:
            out["estimator.vs_reference_rms_m"] = Measured(
                rms(err), f"{np.isfinite(err).sum()} {source} samples in the air, "
                f"mean {np.nanmean(err):+.3f} m", source)
    return out


def truth_origin_m(fs: FlightSeries, t: np.ndarray, alt: np.ndarray) -> float:
    """Truth starts at the vehicle's first fix: subtract its height on the floor less the
    height at which the estimator says a vehicle rests (as `gcs.scoring.truth_origin_m`)."""
    rest = float(fs.setup.get("estimator", {}).get("rest_alt_m", 0.0) or 0.0)
    ground = alt[~flying(fs, t) & np.isfinite(alt)]
    take_off = next((ts for ts, state, _r in fs.states if state == "takeoff"), None)
    if take_off is not None:
        ground = alt[(t < take_off) & np.isfinite(alt)]
    return float(np.median(ground)) - rest if ground.size else 0.0


def reference_alt(fs: FlightSeries) -> tuple[tuple[np.ndarray, np.ndarray] | None, str]:
    """Altitude above the floor from ground truth, else motion capture; the source named."""
    for cols, source in ((fs.truth, "truth"), (fs.mocap, "mocap")):
        if len(cols) and np.isfinite(cols["alt"]).any():
            t, alt = cols["t"], cols["alt"]
            keep = np.isfinite(alt)
            t, alt = t[keep], alt[keep]
            origin = truth_origin_m(fs, t, alt) if source == "truth" else 0.0
            return (t, alt - origin), source
    return None, "none"
