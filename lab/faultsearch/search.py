"""The search: sample fault schedules at random, then let Optuna's TPE concentrate on the
near-misses, minimising each run's smallest margin; every run a row.

`search` is the loop; how runs are flown is the caller's (`in_process`, or Ray tasks in
`lab.faultsearch.campaign`), batch by batch, so the same loop serves a test, a bench program and
a campaign. A batch is told to the study before the next is asked for.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from lab.faultsearch.runner import SearchFlight, fly_schedule, result_row
from lab.faultsearch.schedule import dumps
from lab.faultsearch.space import Space

Executor = Callable[[SearchFlight, Space, Sequence[tuple[int, dict[str, Any]]]],
                    list[dict[str, Any]]]


@dataclass(frozen=True, slots=True)
class SearchOptions:
    """How many runs, how many of them at random first, and how."""

    runs: int = 300
    random_runs: int | None = None  # default: a fifth of the runs (at least 10)
    sampler: str = "tpe"  # "tpe" (random first, then TPE) or "random" (the baseline)
    sample_seed: int = 0
    batch: int = 1  # runs asked for at once (the workers' count)
    until: str | None = None  # stop at the first run that violates this property ("any")

    @property
    def startup(self) -> int:
        """Runs sampled at random before TPE models them."""
        return self.random_runs if self.random_runs is not None else max(10, self.runs // 5)


@dataclass(slots=True)
class SearchResult:
    """Every run's row, and the first run (1-based) that violated what was looked for."""

    rows: list[dict[str, Any]] = field(default_factory=list)
    found_at: int | None = None


def run_params(flight: SearchFlight, space: Space, number: int,
               params: dict[str, Any]) -> dict[str, Any]:
    """Fly one run; its row: the run's number, its parameters, its schedule and margins."""
    schedule = space.schedule(params)
    try:
        row = result_row(fly_schedule(flight, int(params["seed"]), schedule))
    except Exception as exc:  # a crash of the station is a finding, never the search's end
        row = {"seed": int(params["seed"]), "property": "crash", "margin": -1.0,
               "note": f"{type(exc).__name__}: {exc}"[:200], "violated": "crash",
               "exit_ok": False, "exit_reason": "crash"}
    row.update({"run": number, "schedule": dumps(schedule).strip(),
                "faults": len(schedule.faults), "profile": flight.profile})
    row.update({f"p.{k}": v for k, v in params.items() if k != "seed"})
    return row


def in_process(flight: SearchFlight, space: Space,
               batch: Sequence[tuple[int, dict[str, Any]]]) -> list[dict[str, Any]]:
    """Fly a batch here, one run after the other."""
    return [run_params(flight, space, n, p) for n, p in batch]


def _violates(row: dict[str, Any], until: str) -> bool:
    names = [v for v in str(row.get("violated") or "").split(",") if v]
    return bool(names) and (until == "any" or until in names)


def search(flight: SearchFlight, space: Space, opts: SearchOptions,
           execute: Executor = in_process,
           on_row: Callable[[dict[str, Any]], None] | None = None) -> SearchResult:
    """Run the search; stop early at the first violation of `opts.until` if given."""
    import warnings

    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    # `group` (a schedule's slots are conditional on their kind) is marked experimental
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    sampler = (optuna.samplers.RandomSampler(seed=opts.sample_seed) if opts.sampler == "random"
               else optuna.samplers.TPESampler(seed=opts.sample_seed,
                                               n_startup_trials=opts.startup,
                                               multivariate=True, group=True,
                                               constant_liar=opts.batch > 1))
    study = optuna.create_study(direction="minimize", sampler=sampler)
    dists = space.distributions()
    out = SearchResult()
    while len(out.rows) < opts.runs and out.found_at is None:
        n = min(opts.batch, opts.runs - len(out.rows))
        trials = [study.ask(dists) for _ in range(n)]
        rows = execute(flight, space, [(t.number + 1, dict(t.params)) for t in trials])
        for t, row in zip(trials, rows, strict=True):
            m = float(row.get("margin", math.inf))
            study.tell(t, m if math.isfinite(m) else 1e3)
            out.rows.append(row)
            if on_row is not None:
                on_row(row)
            if out.found_at is None and opts.until and _violates(row, opts.until):
                out.found_at = int(row["run"])
    return out
