"""A campaign's results file: one row per run, in Parquet (and CSV), read back to resume.

Rows are written whole after every few finished runs (to a temporary file, then renamed), so a
campaign stopped at any moment keeps every run it finished. Resuming reads the file back and
skips the run ids already in it.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lab.campaign.metrics import COLUMNS, NUMERIC_METRICS, OK

RESULTS_NAME = "results.parquet"


def _columns(rows: Sequence[dict[str, Any]], axes: Iterable[str]) -> list[str]:
    axes = list(axes)
    extra = sorted({k for r in rows for k in r} - set(COLUMNS) - set(axes))
    return ["run_id", *axes, *extra, *[c for c in COLUMNS if c != "run_id"]]


def write_results(path: Path, rows: Sequence[dict[str, Any]], axes: Iterable[str],
                  csv: bool = False) -> None:
    """All `rows` to `path` (Parquet), and next to it as CSV with `csv`."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    cols = _columns(rows, axes)
    data: dict[str, list[Any]] = {c: [r.get(c) for r in rows] for c in cols}
    arrays = {}
    for c, values in data.items():
        if c in NUMERIC_METRICS:
            arrays[c] = pa.array([math.nan if v is None else float(v) for v in values],
                                 pa.float64())
        elif all((isinstance(v, int | float) and not isinstance(v, bool)) or v is None
                 for v in values):
            arrays[c] = pa.array(values)
        else:
            arrays[c] = pa.array([None if v is None else str(v) for v in values], pa.string())
    table = pa.table(arrays)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)
    if csv:
        csv_path = path.with_suffix(".csv")
        tmp_csv = csv_path.with_name(csv_path.name + ".tmp")
        pa_csv.write_csv(table, tmp_csv)
        os.replace(tmp_csv, csv_path)


def read_results(path: Path) -> list[dict[str, Any]]:
    """The rows of a results file ([] when there is none yet)."""
    if not path.is_file():
        return []
    import pyarrow.parquet as pq

    return list(pq.read_table(path).to_pylist())


def _fmt(x: float, scale: float = 100.0) -> str:
    return "-" if not math.isfinite(x) else f"{x * scale:.2f}"


def summary_table(rows: Sequence[dict[str, Any]], axes: Sequence[str],
                  metric: str = "rms_error_m") -> str:
    """Runs grouped by every axis but the seed: how many flew, and the metric's median and
    worst (in cm for metres) with the hold's bias and spread."""
    group_axes = [a for a in axes if a != "seed"]
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(tuple(r.get(a) for a in group_axes), []).append(r)
    scale, unit = (100.0, "cm") if metric.endswith("_m") else (1.0, "")
    head = [*group_axes, "runs", "ok", "failed", f"{metric} median{' ' + unit if unit else ''}",
            "worst", "bias median", "std median"]
    lines = [head]
    for key in sorted(groups, key=lambda k: tuple(str(x) for x in k)):
        rs = groups[key]
        ok = [r for r in rs if r.get("status") == OK]

        def med(col: str, rows_: list[dict[str, Any]] = ok) -> float:
            vals = [float(r[col]) for r in rows_ if r.get(col) is not None
                    and math.isfinite(float(r[col]))]
            return float(np.median(vals)) if vals else math.nan

        vals = [float(r[metric]) for r in ok if math.isfinite(float(r.get(metric, math.nan)))]
        worst = max(vals) if vals else math.nan
        lines.append([*(str(k) for k in key), str(len(rs)), str(len(ok)), str(len(rs) - len(ok)),
                      _fmt(med(metric), scale), _fmt(worst, scale),
                      _fmt(med("mean_error_m")), _fmt(med("std_error_m"))])
    widths = [max(len(row[i]) for row in lines) for i in range(len(head))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(row, widths, strict=True))
                     for row in lines)


def mission_summary_table(rows: Sequence[dict[str, Any]], axes: Sequence[str]) -> str:
    """Mission runs grouped by every axis but the seed: how many met their goal, the contacts
    (over every run that measured them) and the closest pass, the flight time, the goal error
    and, for a mapping mission, the map's IoU (median and worst)."""
    group_axes = [a for a in axes if a != "seed"]
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(tuple(r.get(a) for a in group_axes), []).append(r)
    head = [*group_axes, "runs", "ok", "failed", "scored", "contacts", "runs touching",
            "clearance median cm", "closest", "flight s median", "longest", "goal error cm",
            "IoU median", "worst"]
    lines = [head]
    for key in sorted(groups, key=lambda k: tuple(str(x) for x in k)):
        rs = groups[key]

        def vals(col: str, rows_: list[dict[str, Any]] = rs) -> list[float]:
            return [float(r[col]) for r in rows_ if r.get(col) is not None
                    and math.isfinite(float(r[col]))]

        def stat(xs: list[float], f: Any, scale: float = 1.0) -> str:
            return _fmt(float(f(xs)), scale) if xs else "-"

        contacts = vals("collisions")
        ok = sum(r.get("status") == OK for r in rs)
        lines.append([*(str(k) for k in key), str(len(rs)), str(ok), str(len(rs) - ok),
                      str(len(contacts)), str(int(sum(contacts))),
                      str(sum(c > 0 for c in contacts)),
                      stat(vals("min_clearance_m"), np.median, 100.0),
                      stat(vals("min_clearance_m"), min, 100.0),
                      stat(vals("mission_s"), np.median), stat(vals("mission_s"), max),
                      stat(vals("goal_error_m"), np.median, 100.0),
                      stat(vals("iou"), np.median), stat(vals("iou"), min)])
    widths = [max(len(row[i]) for row in lines) for i in range(len(head))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(row, widths, strict=True))
                     for row in lines)
