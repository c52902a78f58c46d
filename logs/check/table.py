"""The check table as text (one row per check) and as plain data for `--json`."""

from __future__ import annotations

import math
from typing import Any

from logs.check.result import CheckResult, Status, worst


def _num(x: float) -> str:
    if math.isnan(x):
        return "-"
    if x == int(x) and abs(x) < 1e6:
        return f"{x:.0f}"
    return f"{x:.3g}" if abs(x) < 0.01 else f"{x:.3f}" if abs(x) < 10 else f"{x:.1f}"


def _limit(r: CheckResult) -> str:
    t = r.threshold
    sign = ">=" if t.worse == "high" else "<="
    return f"warn {sign}{_num(t.warn)} fail {sign}{_num(t.fail)}"


def format_table(name: str, results: list[CheckResult], why: bool = True) -> str:
    """`name` then one line per check: status, check, value unit, limits, detail (and why)."""
    key_w = max(len(r.key) for r in results)
    lines = [f"{name}: {worst(results).value}"]
    for r in results:
        value = f"{_num(r.value)} {r.threshold.unit}" if r.status is not Status.SKIP else "-"
        source = f" [{r.source}]" if r.source else ""
        lines.append(f"  {r.status.value:<4}  {r.key:<{key_w}}  {value:>12}  "
                     f"{_limit(r):<26}  {r.detail}{source}")
        if why and r.status in (Status.WARN, Status.FAIL):
            lines.append(f"  {'':<4}  {'':<{key_w}}  why: {r.threshold.why}")
    counts = {s: sum(1 for r in results if r.status is s) for s in Status}
    lines.append("  " + "  ".join(f"{s.value} {n}" for s, n in counts.items()))
    return "\n".join(lines)


def to_json(name: str, results: list[CheckResult]) -> dict[str, Any]:
    """One file's checks as plain data."""
    return {"file": name, "status": worst(results).value,
            "checks": [r.to_dict() for r in results]}
