"""A grid or random campaign from start to finish: plan, skip what is done, run, keep, report.

The results file is rewritten every `WRITE_EVERY_S` while runs finish and once at the end, so
Ctrl-C (or a crash of the driver) loses at most the runs of the last few seconds; re-running the
same file reads it back and flies only the runs not in it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lab.campaign.metrics import OK
from lab.campaign.mission_run import mission_run
from lab.campaign.plan import plan_runs
from lab.campaign.pool import run_all
from lab.campaign.progress import Progress
from lab.campaign.results import RESULTS_NAME, read_results, write_results
from lab.campaign.run import RunSpec, fly_run
from lab.campaign.types import BaseMission, Campaign

WRITE_EVERY_S = 2.0


@dataclass(slots=True)
class Outcome:
    """What a campaign left: every row in its results file, and whether it finished."""

    rows: list[dict[str, Any]]
    results: Path
    complete: bool
    ran: int
    skipped: int


class RowKeeper:
    """Collects finished rows and keeps the results file up to date."""

    def __init__(self, path: Path, rows: list[dict[str, Any]], axes: list[str], csv: bool,
                 progress: Progress) -> None:
        self.path = path
        self.rows = rows
        self.axes = axes
        self.csv = csv
        self.progress = progress
        self._last_write = time.monotonic()
        self.added = 0

    def __call__(self, row: dict[str, Any]) -> None:
        self.rows.append(row)
        self.added += 1
        self.progress.update(row.get("status") == OK)
        if time.monotonic() - self._last_write >= WRITE_EVERY_S:
            self.flush()

    def flush(self) -> None:
        """Write every row now."""
        write_results(self.path, self.rows, self.axes, self.csv)
        self._last_write = time.monotonic()


def run_campaign(c: Campaign, out_dir: Path, ray: Any, csv: bool = False, quiet: bool = False,
                 runner: Callable[..., dict[str, Any]] | None = None) -> Outcome:
    """Fly the runs of a grid or random campaign not yet in `out_dir`'s results (each with
    `runner`; default: `fly_run`, or `mission_run` for a mission campaign)."""
    if runner is None:
        runner = mission_run if isinstance(c.base, BaseMission) else fly_run
    path = out_dir / RESULTS_NAME
    rows = read_results(path)
    done = {r.get("run_id") for r in rows}
    runs: list[RunSpec] = plan_runs(c)
    todo = [r for r in runs if r.run_id not in done]
    progress = Progress(len(runs), skipped=len(runs) - len(todo), quiet=quiet)
    keeper = RowKeeper(path, rows, list(c.axes), csv, progress)
    complete = True
    try:
        if todo:
            progress.show()
            complete = run_all(ray, runner, todo, (c.base, out_dir, c.name), keeper)
    finally:
        keeper.flush()
        progress.show(final=True)
    return Outcome(rows, path, complete, keeper.added, len(runs) - len(todo))
