"""A campaign's parts once read: its base flight or mission, its axes and its search, and the
one-line error a bad campaign file ends in (`lab.campaign.spec` reads the file into these)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gcs.errors import UsageError

KINDS = ("grid", "random", "search")
TOP_KEYS = {"name", "kind", "samples", "sample_seed", "fly", "mission", "axes", "search"}
FLY_KEYS = {"alt_m": float, "hold_s": float, "step_m": float, "takeoff_delay_s": float,
            "profile": str, "world": str, "config": str, "record": bool,
            "fix_failsafe": bool}
PROFILES = ("apm25", "copter4")
SEARCH_KEYS = {"trials", "seeds", "worlds", "objective", "failed_penalty"}
NUMERIC_FLY = ("alt_m", "hold_s", "step_m", "takeoff_delay_s")
LINK_KEYS = ("loss", "fade", "fade_start_s", "fade_s")


class CampaignError(UsageError):
    """A campaign file that cannot be run (exit code 2)."""


@dataclass(frozen=True, slots=True)
class Range:
    """A random axis: uniform (or log-uniform) in [min, max]; integers if both ends are."""

    lo: float
    hi: float
    log: bool = False
    integer: bool = False


Axis = tuple[Any, ...] | Range


@dataclass(frozen=True, slots=True)
class BaseFlight:
    """What every run flies before the axes change it."""

    alt_m: float = 1.0
    hold_s: float = 30.0
    step_m: float = 0.0
    takeoff_delay_s: float = 0.0
    profile: str = "apm25"
    world: str | None = None  # paths as the file writes them, relative to `root`
    config: str | None = None
    record: bool = False
    fix_failsafe: bool = False  # fly's --fix-failsafe: copter4 ships FS_GCS_ENABLE 0, FS_OPTIONS 16
    root: Path = Path(".")  # the campaign file's directory

    def resolve(self, text: str | None) -> Path | None:
        """A path of the file (None stays None) from wherever the run happens."""
        return None if text is None else self.root / text

    @property
    def world_path(self) -> Path | None:
        """The base world file."""
        return self.resolve(self.world)

    @property
    def config_path(self) -> Path | None:
        """The base station file."""
        return self.resolve(self.config)


@dataclass(frozen=True, slots=True)
class BaseMission:
    """What every run of a mission campaign flies: the mission file, in lockstep."""

    mission: str  # as the file writes it, relative to `root`
    record: bool = False
    root: Path = Path(".")

    @property
    def mission_path(self) -> Path:
        """The mission file."""
        return self.root / self.mission


@dataclass(frozen=True, slots=True)
class SearchSpec:
    """kind = "search": trials, the runs of one trial and what they minimise."""

    trials: int = 20
    seeds: tuple[int, ...] = (1, 2, 3)
    worlds: tuple[str | None, ...] = (None,)  # as written, relative to the file
    objective: str = "rms_error_m"
    failed_penalty: float = 1.0


@dataclass(frozen=True, slots=True)
class Campaign:
    """A validated campaign file."""

    path: Path
    name: str
    kind: str
    base: BaseFlight | BaseMission
    axes: dict[str, Axis]
    samples: int = 0
    sample_seed: int = 0
    search: SearchSpec = field(default_factory=SearchSpec)
