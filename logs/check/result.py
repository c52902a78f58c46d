"""A check's outcome: its number against its threshold, PASS/WARN/FAIL/SKIP, and what it read."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Any

from logs.check.thresholds import Threshold


class Status(enum.Enum):
    """Ordered from best to worst; SKIP means the recording lacks the data."""

    PASS = "PASS"
    WARN = "WARN"
    FAIL = "FAIL"
    SKIP = "SKIP"


@dataclass(frozen=True, slots=True)
class Measured:
    """What a metric read: its value (NaN: not measurable here) and a short note on how."""

    value: float
    detail: str = ""
    source: str = ""  # for the hold and the estimator: truth, mocap, estimate or none


@dataclass(frozen=True, slots=True)
class CheckResult:
    """One row of the table."""

    key: str
    status: Status
    value: float
    threshold: Threshold
    detail: str
    source: str

    def to_dict(self) -> dict[str, Any]:
        """Plain data for `--json`."""
        t = self.threshold
        return {"check": self.key, "status": self.status.value,
                "value": None if math.isnan(self.value) else self.value, "unit": t.unit,
                "warn": t.warn, "fail": t.fail, "worse": t.worse, "why": t.why,
                "detail": self.detail, "source": self.source}


def judge(value: float, t: Threshold) -> Status:
    """PASS/WARN/FAIL of a value against its threshold (SKIP for NaN)."""
    if math.isnan(value):
        return Status.SKIP
    if t.worse == "high":
        return Status.FAIL if value >= t.fail else Status.WARN if value >= t.warn else Status.PASS
    return Status.FAIL if value <= t.fail else Status.WARN if value <= t.warn else Status.PASS


def evaluate(measured: dict[str, Measured], table: dict[str, Threshold]) -> list[CheckResult]:
    """Every check of the table, in its order; a metric not measured is SKIP."""
    out = []
    for key, t in table.items():
        m = measured.get(key, Measured(math.nan, "not in this recording"))
        out.append(CheckResult(key, judge(m.value, t), m.value, t, m.detail, m.source))
    return out


def worst(results: list[CheckResult]) -> Status:
    """FAIL if any failed, else WARN if any warned, else PASS."""
    statuses = {r.status for r in results}
    for s in (Status.FAIL, Status.WARN):
        if s in statuses:
            return s
    return Status.PASS
