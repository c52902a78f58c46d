"""One run of a mission campaign: `mission run --lockstep` with the run's seed and planner keys.

Like `lab.campaign.run.fly_run`, it never raises for a mission that went wrong: a refused file,
a failed mission or a bad value is a row with its reason.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from gcs.mission.options import RunOptions
from lab.campaign.metrics import failed_row, mission_row
from lab.campaign.planner_keys import mission_with
from lab.campaign.run import RunSpec, failure_text, stamped
from lab.campaign.types import BaseMission
from lab.lockstep import install

PLANNER = "planner."


def mission_run(base: BaseMission, run: RunSpec, output: Path, campaign: str) -> dict[str, Any]:
    """Fly one run's mission in lockstep; its row (status "ok" when the goal was met)."""
    from gcs.mission.runner import run_mission

    install()  # a worker process flies lockstep on the bundled SITL

    c0, w0 = time.process_time(), time.perf_counter()
    values = run.values
    try:
        planner = {k.removeprefix(PLANNER): v for k, v in values.items()
                   if k.startswith(PLANNER)}
        spec = mission_with(base.mission_path, planner)
        options = RunOptions(lockstep=True, record=base.record,
                             output=output / "missions" / run.run_id,
                             seed=int(values.get("seed", 0)))
        report = run_mission(spec, options, None)
        row = mission_row(run.run_id, values, report.to_dict(), report.ok)
    except Exception as exc:  # a failed run is a row with its reason, never the campaign's end
        row = failed_row(run.run_id, values, failure_text(exc))
    return stamped(row, c0, w0)
