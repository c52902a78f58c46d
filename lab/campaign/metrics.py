"""One campaign run's row: the axes' values, its status and reason, and every metric `fly` or
`mission run` prints.

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
    "collisions": "mission: contacts with the world's boxes begun (error_source says from what)",
    "min_clearance_m": "mission: closest the body came to a box, m",
    "goal_error_m": "mission: distance from the goal where it ended, m",
    "mission_s": "mission: flight time from take-off, s",
    "steps": "mission: planner steps",
    "path_length_m": "mission: length of the path flown, m",
    "iou": "mission: radiation map's overlap with the true contour",
    "samples": "mission: radiation samples taken",
    "sim_s": "simulated time of the run, s",
    "cpu_s": "CPU time of the run, s",
    "wall_s": "wall time of the run, s",
}
TEXT_METRICS = ("status", "reason", "error_source", "worker", "sitl")
COLUMNS = ("run_id", *TEXT_METRICS, *NUMERIC_METRICS)
OK = "ok"
FAILED = "failed"


def failed_row(run_id: str, values: dict[str, Any], reason: str) -> dict[str, Any]:
    """A run that did not fly as commanded (or did not run): its reason, no numbers."""
    row: dict[str, Any] = {k: math.nan for k in NUMERIC_METRICS}
    row.update(values)
    row.update(run_id=run_id, status=FAILED, reason=reason, error_source="none", worker="",
               sitl="")
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


MISSION_KEYS = {"collisions": "collisions", "min_clearance_m": "truth_min_clearance_m",
                "goal_error_m": "goal_error_m", "mission_s": "duration_s", "steps": "steps",
                "path_length_m": "path_length_m", "iou": "iou", "samples": "samples",
                "sim_s": "duration_s"}


def mission_row(run_id: str, values: dict[str, Any], report: dict[str, Any],
                ok: bool) -> dict[str, Any]:
    """A mission that ran: `mission run --json`'s report in the row; failed (with the report's
    reason) when the goal was not met. Collisions name their source: the SITL's truth, or none
    (then the column is NaN, not a zero nobody measured)."""
    row = failed_row(run_id, values, "" if ok else str(report.get("reason", "")))
    row["status"] = OK if ok else FAILED
    source = str(report.get("collision_source", "none"))
    row["error_source"] = source
    for column, key in MISSION_KEYS.items():
        v = report.get(key)
        if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
            row[column] = float(v)
    if source == "none":
        row["collisions"] = row["min_clearance_m"] = math.nan
    return row
