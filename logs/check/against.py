"""One flight's metrics placed in a campaign's distribution of the same metrics.

A campaign's rows (its `results.parquet`, read by the caller) carry, for each run it flew, the
check metrics of that run's recording as `check.<key>` columns (and the flight summary's own
columns). For each metric both have, the flight's percentile among the campaign's runs is given,
and the flight is flagged when it lies beyond the campaign's worst run on the metric's bad side
(its threshold's `worse`). A metric with fewer than `MIN_RUNS` values in the campaign is left out.
The flight's station settings are compared with the campaign's too (`settings_differences`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from logs.check.result import Measured
from logs.check.thresholds import Threshold

COLUMN_PREFIX = "check."
MIN_RUNS = 3
# settings of the process, not of the flight: a real flight at real-time priority compares
# fairly with a lockstep campaign that runs without it
NOT_FLIGHT_SETTINGS = frozenset({"realtime_priority", "gil_switch_interval_s", "events_kept"})


@dataclass(frozen=True, slots=True)
class Placement:
    """The flight's value of one metric among the campaign's."""

    key: str
    value: float
    percentile: float  # share of campaign runs at or below the value, %
    campaign_best: float
    campaign_median: float
    campaign_worst: float
    runs: int
    flagged: bool  # beyond the campaign's worst run

    def to_dict(self) -> dict[str, Any]:
        """Plain data for `--json`."""
        return asdict(self)


def campaign_values(rows: Sequence[Mapping[str, Any]]) -> dict[str, np.ndarray]:
    """The check metrics of the campaign's flown runs, by key."""
    out: dict[str, list[float]] = {}
    for row in rows:
        if row.get("status", "ok") != "ok":
            continue
        for column, value in row.items():
            if not column.startswith(COLUMN_PREFIX):
                continue
            if isinstance(value, int | float) and not isinstance(value, bool) \
                    and math.isfinite(value):
                out.setdefault(column.removeprefix(COLUMN_PREFIX), []).append(float(value))
    return {k: np.asarray(v) for k, v in out.items()}


def place(measured: Mapping[str, Measured], rows: Sequence[Mapping[str, Any]],
          table: Mapping[str, Threshold]) -> list[Placement]:
    """Every metric the flight and the campaign both have, in the table's order."""
    values = campaign_values(rows)
    out = []
    for key, t in table.items():
        m = measured.get(key)
        camp = values.get(key)
        if m is None or math.isnan(m.value) or camp is None or camp.size < MIN_RUNS:
            continue
        high = t.worse == "high"
        worst_v = float(camp.max() if high else camp.min())
        best_v = float(camp.min() if high else camp.max())
        # a run equal to the worst is not beyond it; counts of events need a whole one more
        flagged = m.value > worst_v if high else m.value < worst_v
        out.append(Placement(key, m.value, 100.0 * float(np.mean(camp <= m.value)), best_v,
                             float(np.median(camp)), worst_v, int(camp.size), flagged))
    return out


def format_placements(campaign: str, placements: Sequence[Placement]) -> str:
    """The comparison as text, one metric a line."""
    if not placements:
        return f"against {campaign}: no metric in common"
    flagged = [p for p in placements if p.flagged]
    head = (f"against {campaign}: {len(flagged)} of {len(placements)} metrics beyond the "
            f"campaign's worst run")
    key_w = max(len(p.key) for p in placements)
    lines = [head]
    for p in placements:
        mark = "BEYOND" if p.flagged else "within"
        lines.append(f"  {mark:<6}  {p.key:<{key_w}}  {p.value:10.4g}  percentile "
                     f"{p.percentile:5.1f}  campaign best {p.campaign_best:.4g} median "
                     f"{p.campaign_median:.4g} worst {p.campaign_worst:.4g} ({p.runs} runs)")
    return "\n".join(lines)


def check_columns(measured: Mapping[str, Measured]) -> dict[str, float]:
    """A run's metrics as the campaign's row columns (`check.<key>`)."""
    return {COLUMN_PREFIX + k: m.value for k, m in measured.items() if not math.isnan(m.value)}


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(_flatten(value, name + "."))
        else:
            out[name] = value
    return out


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, int | float) and isinstance(b, int | float):
        return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
    return bool(a == b)


def settings_differences(flight: Mapping[str, Any], campaign: Mapping[str, Any],
                         varied: Sequence[str] = ()) -> list[str]:
    """The station settings (a recording's `/gcs/setup` configuration) in which the flight
    differs from the campaign's runs, other than those the campaign itself varied (its
    `station.*` axes): "altitude.gains.kp 4.5 (campaign 9)". Comparing a flight with a
    campaign flown otherwise compares two different stations."""
    mine, theirs = _flatten(flight), _flatten(campaign)
    skip = {v.removeprefix("station.") for v in varied} | NOT_FLIGHT_SETTINGS
    out = []
    for key in sorted(set(mine) | set(theirs)):
        if key in skip:
            continue
        a, b = mine.get(key), theirs.get(key)
        if not _same(a, b):
            out.append(f"{key} {a!r} (campaign {b!r})")
    return out
