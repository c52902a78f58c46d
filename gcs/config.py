"""Station configuration: frozen dataclasses with the thesis's values, overridable from TOML.

A TOML file mirrors the dataclasses' nesting, e.g.

    period_s = 0.025
    estimator_kind = "kalman"
    [altitude]
    mass_kg = 1.63
    [altitude.gains]
    kp = 4.0

Unknown keys and wrong types are errors that name the file and the key.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from gcs.control.altitude_controller import AltitudeControllerParams
from gcs.control.climb_rate_hold import ClimbRateHoldParams
from gcs.control.position_controller import PositionControllerParams
from gcs.errors import UsageError
from gcs.estimation import EstimatorParams
from gcs.toml_file import read_toml

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

_D = TypeVar("_D", bound="DataclassInstance")


class EstimatorKind(enum.Enum):
    """Which altitude estimator flies."""

    KALMAN = "kalman"
    COMPLEMENTARY = "complementary"
    DEAD_RECKONING = "dead_reckoning"


class HoldMode(enum.Enum):
    """How the PC flies the altitude hold (gcs.supervisor.climb_mode)."""

    THROTTLE = "throttle"  # STABILIZE, the PID's acceleration as a direct throttle (thesis ch. 7)
    CLIMB_RATE = "climb-rate"  # the firmware's ALT_HOLD, the loop asking a climb rate


@dataclass(frozen=True, slots=True)
class FlightProfile:
    """How `fly` takes off, holds and lands."""

    takeoff_climb_mps: float = 0.5  # setpoint ramp while taking off
    # where a hold asked on the floor with no altitude of its own (the TUI's `h`) climbs to;
    # never below the sonar's blind band plus a margin (the supervisor raises it there)
    takeoff_alt_m: float = 1.0
    land_descent_mps: float = 0.3
    land_handover_alt_m: float = 0.15  # below this, LAND mode / throttle down finishes the job
    settle_s: float = 4.0  # after reaching the hold altitude, before the hold is scored

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            if getattr(self, f.name) <= 0.0:
                raise ValueError(f"{f.name} must be > 0")


@dataclass(frozen=True, slots=True)
class StationConfig:
    """Everything the station's loop needs; thesis values as defaults (25 ms period)."""

    period_s: float = 0.025
    estimator_kind: EstimatorKind = EstimatorKind.KALMAN
    # sonar 5 cm below the centre of gravity, which stands 6 cm above the floor on its skids
    estimator: EstimatorParams = field(
        default_factory=lambda: EstimatorParams(sonar_offset_m=0.05, rest_alt_m=0.06)
    )
    altitude: AltitudeControllerParams = field(default_factory=AltitudeControllerParams)
    hold_mode: HoldMode = HoldMode.THROTTLE
    climb: ClimbRateHoldParams = field(default_factory=ClimbRateHoldParams)
    position: PositionControllerParams = field(default_factory=PositionControllerParams)
    flight: FlightProfile = field(default_factory=FlightProfile)
    events_kept: int = 200
    realtime_priority: int = 10  # SCHED_FIFO priority of the loop thread where allowed; 0: off
    gil_switch_interval_s: float = 0.0005  # so other threads give the loop the GIL quickly

    def __post_init__(self) -> None:
        if not 0.001 <= self.period_s <= 1.0:
            raise ValueError(f"period_s must be in [0.001, 1], got {self.period_s}")
        if not 0 <= self.realtime_priority <= 99:
            raise ValueError(f"realtime_priority must be in 0..99, got {self.realtime_priority}")
        if not 0.0 < self.gil_switch_interval_s <= 0.1:
            raise ValueError("gil_switch_interval_s must be in (0, 0.1]")


def _build(base: _D, data: dict[str, Any], where: str) -> _D:
    """`base` (a dataclass instance) with the fields in `data` replaced, checked and converted."""
    cls = type(base)
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key not in names:
            raise UsageError(f"{where}{key}: unknown key; expected one of {sorted(names)}")
        kwargs[key] = _convert(hints[key], getattr(base, key), value, f"{where}{key}")
    try:
        return dataclasses.replace(base, **kwargs)
    except (TypeError, ValueError) as exc:
        raise UsageError(f"{where.rstrip('. ')}: {exc}") from None


def _convert(hint: Any, default: Any, value: Any, where: str) -> Any:
    if dataclasses.is_dataclass(hint):
        if not isinstance(value, dict):
            raise UsageError(f"{where}: expected a table, got {value!r}")
        return _build(default, value, where + ".")
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        try:
            return hint(value)
        except ValueError:
            allowed = [m.value for m in hint]
            raise UsageError(f"{where}: expected one of {allowed}, got {value!r}") from None
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise UsageError(f"{where}: expected a number, got {value!r}")
        if not math.isfinite(float(value)):
            raise UsageError(f"{where}: expected a finite number, got {value!r}")
        return float(value)
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise UsageError(f"{where}: expected an integer, got {value!r}")
        return value
    return value


def load_config(path: str | Path | None) -> StationConfig:
    """Defaults, overridden by the TOML file at `path` (None: defaults only)."""
    if path is None:
        return StationConfig()
    p = Path(path)
    data = read_toml(p, label=str(p), noun="config file")
    return _build(StationConfig(), data, f"{p}: ")


def config_from_table(data: dict[str, Any], where: str = "") -> StationConfig:
    """Defaults overridden by a station TOML's table as parsed (`where` prefixes an error's
    key, e.g. the file it came from)."""
    return _build(StationConfig(), data, where)
