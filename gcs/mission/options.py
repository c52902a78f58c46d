"""How a mission is run: the command line's choices, handed to the runner and the executor."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True, slots=True)
class RunOptions:
    """How to run a mission (the CLI's flags)."""

    kinematic: bool = False
    connect: str | None = None
    connect_timeout_s: float = 30.0  # how long `connect` is waited for (firmware_link.wait_up)
    arm_timeout_s: float | None = None  # None: the mission file's flight.arm_timeout_s
    mocap: str | None = None
    record: bool = True
    output: Path = Path("flights")
    plot: Path | None = None
    speedup: float | None = None  # None: the mission file's
    seed: int | None = None
    fix_failsafe: bool = False  # the pilot's consent to set unsafe GCS-failsafe parameters
    foxglove: str | None = None  # [HOST:]PORT: serve the mission live to Foxglove
    forward: tuple[str, ...] = ()  # other ground stations sharing the vehicles
    # False (--no-truth): the station and the planner never see the world's sources or boxes
    # (the SITL or the kinematic world still simulates them) and nothing is scored against them
    truth: bool = True
    # the bundled SITL in this process on simulated time (`mission run --lockstep`)
    lockstep: bool = False
    # lockstep only: the vehicle links' faults (gcs.lockstep.LockstepOptions.faults: a fade of
    # one way or both at a simulated time, frame loss, and which vehicles suffer them)
    link_faults: dict[str, Any] | None = None
