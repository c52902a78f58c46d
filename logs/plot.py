"""The thesis's Fig. 7.1 view of a flight: heights on top, throttle, vertical acceleration below.

Panel 1: altitude setpoint, the station's estimate, the sonar and (in SITL) the true altitude.
Panel 2: the throttle the station commanded. Panel 3: vertical acceleration, the estimator's
bias-corrected value and the raw IMU's (level approximation), as the thesis compared the
accelerometer with the sonar. matplotlib is optional and imported only here, only when called.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from logs.errors import RecordingError
from logs.reader import Recording
from logs.signals import SIGNALS, Signal

MATPLOTLIB_MISSING = "matplotlib is not installed: pip install quadgcs[plot]"


class PlotUnavailable(RuntimeError):
    """matplotlib is missing (the optional `plot` extra)."""


@dataclass(frozen=True, slots=True)
class Series:
    """One signal over time, seconds from the recording's start."""

    signal: Signal
    t_s: np.ndarray
    values: np.ndarray


def extract_series(recording: Recording) -> dict[str, Series]:
    """Every standard signal present in the recording, as arrays."""
    by_topic: dict[str, list[Signal]] = {}
    for s in SIGNALS:
        if s.topic in recording.counts:
            by_topic.setdefault(s.topic, []).append(s)
    samples: dict[str, tuple[list[float], list[float]]] = {s.name: ([], []) for s in SIGNALS}
    start_ns = recording.start_ns
    if by_topic:
        for topic, log_ns, message in recording.messages(list(by_topic)):
            t = (log_ns - start_ns) / 1e9
            for s in by_topic[topic]:
                value = s.read(message)
                ts, vs = samples[s.name]
                ts.append(t)
                vs.append(value)
    out: dict[str, Series] = {}
    for s in SIGNALS:
        t_arr = np.asarray(samples[s.name][0])
        v_arr = np.asarray(samples[s.name][1], dtype=float)
        # missing samples (a message without this field, an invalid sonar) would break the line
        keep = np.isfinite(v_arr)
        if keep.any():
            out[s.name] = Series(s, t_arr[keep], v_arr[keep])
    return out


_PANELS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("altitude (m, up)", ("alt_setpoint_m", "alt_estimate_m", "sonar_m", "truth_alt_m")),
    ("throttle (µs)", ("throttle_us",)),
    ("vertical acc. (m/s², up)", ("acc_up_imu_mps2", "acc_up_est_mps2")),
)


def plot_flight(recording: Recording, out: str | os.PathLike[str], *, dpi: int = 120) -> Path:
    """Draw the flight to an image file (PNG, SVG or PDF by suffix)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise PlotUnavailable(MATPLOTLIB_MISSING) from exc
    series = extract_series(recording)
    if not series:
        topics = ", ".join(sorted({s.topic for s in SIGNALS}))
        raise RecordingError(f"{recording.path}: nothing to plot (none of the topics {topics})")
    out_path = Path(out)
    fig, axes = plt.subplots(len(_PANELS), 1, sharex=True, figsize=(10, 8))
    try:
        for ax, (ylabel, names) in zip(axes, _PANELS, strict=True):
            drawn = False
            for name in names:
                s = series.get(name)
                if s is None:
                    continue
                style = {"lw": 0.8} if name != "sonar_m" else {"lw": 0, "marker": ".", "ms": 2}
                ax.plot(s.t_s, s.values, label=s.signal.label, **style)
                drawn = True
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            if drawn:
                ax.legend(loc="upper right", fontsize="small")
            else:
                ax.text(0.5, 0.5, "not recorded", ha="center", va="center", transform=ax.transAxes)
        axes[-1].set_xlabel("time since start (s)")
        meta = recording.metadata
        fig.suptitle(f"{recording.path.name}  {meta.get('vehicle', '')}".strip())
        fig.tight_layout()
        try:
            fig.savefig(out_path, dpi=dpi)
        except (OSError, ValueError) as exc:
            raise RecordingError(f"{out_path}: cannot write the plot: {exc}") from exc
    finally:
        plt.close(fig)
    return out_path
