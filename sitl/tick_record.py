"""The decorator for the SITL's per-tick value types (sensor samples, truth, controller terms).

A slotted dataclass that is not frozen: one of each is built every simulation tick, and a frozen
dataclass's `__init__` (an `object.__setattr__` per field) costs about three times a plain one's,
which in lockstep was a few per cent of a whole flight. Nothing changes a record once built.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar, dataclass_transform

T = TypeVar("T")


@dataclass_transform()
def tick_record(cls: type[T]) -> type[T]:
    """`@dataclass(slots=True)`, the one place that says why not frozen."""
    return dataclass(slots=True)(cls)
