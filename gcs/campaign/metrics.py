"""One campaign run's row: the axes' values, its status and reason, and every metric `fly` prints.

The columns are fixed (`COLUMNS`), so a results file has the same schema whatever the runs did:
a failed run has its reason and NaN where a flight would have had numbers.
"""

from __future__ import annotations

import math
from typing import Any

NUMERIC_METRICS: dict[str, str] = {
    "rms_error_m": "hold error RMS against the setpoint, m",
    "max_error_m": "worst |hold error|, m",
    "mean_error_m": "hold bias, m",
    "std_error_m": "hold spread about its bias, m",
    "truth_coverage": "share of the hold scored against truth",
    "overshoot_pct": "step overshoot, %",
    "settle_time_s": "step settle time, s",
    "hover_throttle": "hover throttle the station learned",
    "link_down_s": "time the link was lost, s",
    "ticks": "station ticks",
    "rx_messages": "MAVLink messages received",
    "lost_messages": "MAVLink messages lost",
    "corrupted_frames": "corrupted frames",
    "sim_s": "simulated time of the run, s",
    "cpu_s": "CPU time of the run, s",
    "wall_s": "wall time of the run, s",
}
TEXT_METRICS = ("status", "reason", "error_source", "worker")
COLUMNS = ("run_id", *TEXT_METRICS, *NUMERIC_METRICS)
OK = "ok"
FAILED = "failed"


def failed_row(run_id: str, values: dict[str, Any], reason: str) -> dict[str, Any]:
    """A run that did not fly as commanded (or did not run): its reason, no numbers."""
    row: dict[str, Any] = {k: math.nan for k in NUMERIC_METRICS}
    row.update(values)
    row.update(run_id=run_id, status=FAILED, reason=reason, error_source="none", worker="")
    return row


def flown_row(run_id: str, values: dict[str, Any], summary: dict[str, Any]) -> dict[str, Any]:
    """A run that flew: `fly --json`'s summary flattened into the row."""
    row = failed_row(run_id, values, "")
    row["status"] = OK
    row["error_source"] = str(summary.get("error_source", "none"))
    for key in NUMERIC_METRICS:
        v = summary.get(key)
        if isinstance(v, int | float) and not isinstance(v, bool):
            row[key] = float(v)
    step = summary.get("step") or {}
    for key in ("overshoot_pct", "settle_time_s"):
        v = step.get(key)
        if isinstance(v, int | float):
            row[key] = float(v)
    return row
