"""The space a fault search samples: a run's seed and a few fault slots, each a kind (or none),
an anchor (a simulated time over the whole flight, or a phase), an offset, a length and a size,
as numbers in 0..1 that Optuna can model; and the shrinking of a violating schedule.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

from lab.faultsearch.schedule import KINDS, PHASES, Fault, Schedule

NONE = "none"
TIME = "time"
PHASE_WINDOW_S = 6.0  # a fault timed to a phase starts within this of it
MIN_LENGTH_S = 0.05


@dataclass(frozen=True, slots=True)
class Space:
    """What a search varies (the campaign file's [faults] table, with its defaults)."""

    kinds: tuple[str, ...] = tuple(KINDS)
    anchors: tuple[str, ...] = (TIME, *PHASES)
    slots: int = 2  # faults per run at most
    span_s: float = 45.0  # the flight, for faults timed from the SITL's start
    max_length_s: float = 10.0
    seeds: tuple[int, int] = (1, 10_000)

    def distributions(self) -> dict[str, Any]:
        """Optuna's distributions of every parameter."""
        from optuna.distributions import (
            CategoricalDistribution,
            FloatDistribution,
            IntDistribution,
        )

        d: dict[str, Any] = {"seed": IntDistribution(*self.seeds)}
        for i in range(self.slots):
            d[f"f{i}.kind"] = CategoricalDistribution([NONE, *self.kinds])
            d[f"f{i}.anchor"] = CategoricalDistribution(list(self.anchors))
            d[f"f{i}.offset"] = FloatDistribution(0.0, 1.0)
            d[f"f{i}.length"] = FloatDistribution(0.0, 1.0)
            d[f"f{i}.size"] = FloatDistribution(0.0, 1.0)
        return d

    def schedule(self, params: dict[str, Any]) -> Schedule:
        """The schedule the parameters describe."""
        faults = []
        for i in range(self.slots):
            kind = params[f"f{i}.kind"]
            if kind == NONE:
                continue
            k = KINDS[kind]
            anchor = params[f"f{i}.anchor"]
            off = float(params[f"f{i}.offset"])
            start = off * (self.span_s if anchor == TIME else PHASE_WINDOW_S)
            # lengths log-uniform: a 0.1 s burst is as interesting as a 10 s fade
            frac = float(params[f"f{i}.length"])
            length = 0.0 if k.event else MIN_LENGTH_S * (self.max_length_s / MIN_LENGTH_S) ** frac
            size = k.lo + float(params[f"f{i}.size"]) * (k.hi - k.lo) if k.size else 0.0
            faults.append(Fault(kind, _r(start), None if anchor == TIME else anchor,
                                _r(length), _r(size)))
        return Schedule(tuple(faults))


def _r(x: float) -> float:
    """Rounded to a millisecond (a millivolt...): what a schedule file shows is what flew."""
    return round(x, 3)


def shrink(schedule: Schedule, violates: Callable[[Schedule], bool],
           budget: int = 12) -> tuple[Schedule, int]:
    """The fewest, shortest faults that still violate (greedy): drop each fault (all of them,
    when the seed violates without any), then halve each
    length while it still violates. `violates` flies a candidate; at most `budget` flights.
    The smallest schedule found and the flights it took."""
    best = schedule
    tried = 0
    i = 0
    # down to no fault at all: a seed that violates on its own is a finding of its own
    while i < len(best.faults) and tried < budget:
        cand = Schedule(best.faults[:i] + best.faults[i + 1:])
        tried += 1
        if violates(cand):
            best = cand
        else:
            i += 1
    for i, f in enumerate(best.faults):
        while f.length_s > 2 * MIN_LENGTH_S and tried < budget:
            shorter = replace(f, length_s=_r(f.length_s / 2.0))
            cand = Schedule((*best.faults[:i], shorter, *best.faults[i + 1:]))
            tried += 1
            if not violates(cand):
                break
            best, f = cand, shorter
    return best, tried


def params_text(params: dict[str, Any]) -> str:
    """The parameters, short, for a log line."""
    return " ".join(f"{k}={v:.3g}" if isinstance(v, float) and math.isfinite(v) else f"{k}={v}"
                    for k, v in params.items())
