"""`quadgcs logs check`: an automatic review of a recorded flight, check by check.

`FlightSeries` gathers what the checks read; `measure` turns it into numbers; `evaluate` judges
them against the thresholds table (`thresholds.py`); `table.py`, `html.py` and `against.py`
present them. Everything here is pure: reading files and decoding MAVLink happen in the caller.
"""

from logs.check.metrics_flight import (
    control_metrics,
    event_metrics,
    hold_metrics,
    power_metrics,
    vibration_metrics,
)
from logs.check.metrics_link import estimator_metrics, link_metrics, loop_metrics
from logs.check.result import CheckResult, Measured, Status, evaluate, judge, worst
from logs.check.series import TOPICS, FlightSeries, FrameInfo
from logs.check.thresholds import DEFAULTS, Threshold, ThresholdError, load_thresholds


def measure(fs: FlightSeries) -> dict[str, Measured]:
    """Every metric the recording has the data for."""
    out: dict[str, Measured] = {}
    for fn in (link_metrics, loop_metrics, estimator_metrics, vibration_metrics,
               control_metrics, power_metrics, event_metrics, hold_metrics):
        out.update(fn(fs))
    return out


__all__ = [
    "DEFAULTS",
    "TOPICS",
    "CheckResult",
    "FlightSeries",
    "FrameInfo",
    "Measured",
    "Status",
    "Threshold",
    "ThresholdError",
    "evaluate",
    "judge",
    "load_thresholds",
    "measure",
    "worst",
]
