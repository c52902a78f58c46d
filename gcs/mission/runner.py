"""Run a mission file: pick the world, the planner and where it flies, return the report."""

from __future__ import annotations

import contextlib
import dataclasses
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from gcs.errors import UsageError
from gcs.mission.executor import run_on_vehicles
from gcs.mission.kinematic import run_kinematic
from gcs.mission.options import RunOptions
from gcs.mission.outcome import Outcome
from gcs.mission.planner_params import PlannerSetup, planner_setup
from gcs.mission.plot import write_radiation_products
from gcs.mission.recording import SUMMARY, MissionRecording
from gcs.mission.report import MissionReport
from gcs.mission.spec import MissionSpec, PlannerKind
from gcs.mission.world import MissionWorld, load_world

if TYPE_CHECKING:  # the recorder's module is imported only when a recording is asked for
    from logs import Recorder


def mission_world(spec: MissionSpec) -> MissionWorld:
    """The mission's world (required: the planners and the evaluation need it)."""
    if spec.world_path is None:
        raise UsageError(f"{spec.path}: world: missing; expected world = \"../worlds/NAME.toml\"")
    return load_world(spec.world_path)


def _open_recorder(spec: MissionSpec, options: RunOptions, mode: str) -> Recorder:
    from logs import Recorder, RecordingError

    meta = {"command": "mission", "mission": spec.name, "planner": spec.planner.value,
            "mode": mode, "mission_file": str(spec.path), "mission_text": spec.text}
    try:
        # the kinematic world runs as fast as it computes: the recorder makes it wait, never drops
        return Recorder(options.output, metadata=meta, vehicle=f"mission-{spec.name}",
                        block_when_full=mode == "kinematic")
    except RecordingError as exc:
        raise UsageError(f"-o {options.output}: {exc}") from None


def run_mission(spec: MissionSpec, options: RunOptions,
                progress: Callable[[str], None] | None = None) -> MissionReport:
    """Fly the mission (kinematic world or vehicle), record it, write the plot; the report."""
    mw = mission_world(spec)
    setup = planner_setup(spec, mw.world.room.min_n[:2], mw.world.room.max_n[:2])
    if options.seed is not None:
        setup = dataclasses.replace(setup, seed=options.seed)
    if not options.kinematic:
        report, outcome = run_on_vehicles(spec, mw, setup, options, progress)
    else:
        report, outcome = _run_kinematic(spec, mw, setup, options, progress)
    if spec.planner is PlannerKind.RADIATION and outcome.products is not None \
            and outcome.products[1] is not None:
        report.metrics.update(write_radiation_products(spec, options, report, outcome.products))
    return report


def _run_kinematic(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                   options: RunOptions,
                   progress: Callable[[str], None] | None) -> tuple[MissionReport, Outcome]:
    """The kinematic world, recorded (and shown live) as the options ask."""
    with contextlib.ExitStack() as stack:
        live = None
        if options.foxglove is not None:  # opened first, closed last: it gets every message
            from gcs.foxglove_feed import open_live

            live = open_live(options.foxglove)
            stack.callback(live.close)
            print(f"foxglove: live view on {live.url}", file=sys.stderr, flush=True)
        recorder = _open_recorder(spec, options, "kinematic") if options.record else None
        if recorder is not None:
            stack.callback(recorder.close)
            if live is not None:
                recorder.add_tap(live.publish)  # the recording's JSON, not encoded twice
        rec = MissionRecording(recorder if recorder is not None else live)
        report, outcome = run_kinematic(spec, mw, setup, rec, progress, truth=options.truth)
        rec.put(SUMMARY, time.monotonic(), report.to_dict())
    return report, outcome
