"""kind = "search": station gains proposed by Optuna's TPE sampler, each trial flown on Ray.

A trial is one set of axis values flown on every seed (and world) of `[search]`; its objective is
the mean over those runs of the chosen metric, a failed run counting as `failed_penalty`. Trials
go out in batches as wide as the cluster's CPUs allow; each run is a row in the results file
with its trial's number, so a stopped search resumes: complete trials are told to a new study
before it asks for more. The best trial's station values are written as a station TOML that
`quadgcs fly --config` reads (fly.* values, which no station file holds, in its header).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gcs.errors import RuntimeFault
from lab.campaign.driver import Outcome, RowKeeper
from lab.campaign.metrics import OK
from lab.campaign.plots import history_plot
from lab.campaign.pool import need, run_all
from lab.campaign.progress import Progress
from lab.campaign.results import RESULTS_NAME, read_results
from lab.campaign.run import RunSpec, fly_run, make_run
from lab.campaign.tables import dumps, set_dotted, station_table
from lab.campaign.types import BaseFlight, Campaign, Range

BEST_NAME = "best_station.toml"
HISTORY_NAME = "search_history.png"


@dataclass(slots=True)
class SearchOutcome:
    """A search's rows and its best trial."""

    outcome: Outcome
    best_value: float
    best_params: dict[str, Any]
    best_config: Path
    history: Path | None
    trials: int


def _distributions(c: Campaign) -> dict[str, Any]:
    from optuna.distributions import (
        CategoricalDistribution,
        FloatDistribution,
        IntDistribution,
    )

    out: dict[str, Any] = {}
    for name, axis in c.axes.items():
        if isinstance(axis, Range):
            out[name] = (IntDistribution(int(axis.lo), int(axis.hi), log=axis.log)
                         if axis.integer else FloatDistribution(axis.lo, axis.hi, log=axis.log))
        else:
            out[name] = CategoricalDistribution(list(axis))
    return out


def trial_runs(c: Campaign, number: int, params: dict[str, Any]) -> list[RunSpec]:
    """The runs of one trial: its values on every seed and world."""
    runs = []
    for world in c.search.worlds:
        for seed in c.search.seeds:
            values: dict[str, Any] = {**params, "seed": seed}
            if world is not None:
                values["world"] = world
            run = make_run(c.base, values)
            runs.append(RunSpec(run.run_id, {**values, "trial": number}))
    return runs


def objective(c: Campaign, rows: list[dict[str, Any]]) -> float:
    """Mean of the metric over a trial's runs, a failed one counting as the penalty."""
    vals = []
    for r in rows:
        v = float(r.get(c.search.objective, math.nan))
        vals.append(v if r.get("status") == OK and math.isfinite(v) else c.search.failed_penalty)
    return sum(vals) / len(vals) if vals else math.inf


def run_search(c: Campaign, out_dir: Path, ray: Any, csv: bool = False, quiet: bool = False,
               runner: Callable[..., dict[str, Any]] = fly_run) -> SearchOutcome:
    """Run the search's trials (those not already in the results) and write the best."""
    optuna = need("optuna")

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    dists = _distributions(c)
    study = optuna.create_study(direction="minimize",
                                sampler=optuna.samplers.TPESampler(seed=c.sample_seed))
    path = out_dir / RESULTS_NAME
    rows = read_results(path)
    per_trial = len(c.search.seeds) * len(c.search.worlds)
    skipped = _resume(c, study, dists, rows, per_trial)
    total = c.search.trials * per_trial
    progress = Progress(total, skipped=skipped * per_trial, quiet=quiet)
    keeper = RowKeeper(path, rows, [*c.axes, "seed", "world", "trial"], csv, progress)
    cpus = int(ray.cluster_resources().get("CPU", 1))
    batch = max(1, math.ceil(cpus / per_trial))
    complete = True
    try:
        progress.show()
        while complete and len(study.trials) < c.search.trials:
            asked = [study.ask(dists) for _ in range(min(batch, c.search.trials
                                                         - len(study.trials)))]
            runs = [r for t in asked for r in trial_runs(c, t.number, t.params)]
            complete = run_all(ray, runner, runs, (c.base, out_dir, c.name), keeper)
            if not complete:
                break
            for t in asked:
                study.tell(t, objective(c, [r for r in rows if r.get("trial") == t.number]))
    finally:
        keeper.flush()
        progress.show(final=True)
    values = [float(t.value) for t in study.trials if t.value is not None]
    if not values:
        raise RuntimeFault("the search finished no trial")
    best = study.best_trial
    best_value = float(best.value if best.value is not None else math.inf)
    best_path = write_best(c, best.params, best_value, out_dir / BEST_NAME, len(values))
    history = history_plot(values, f"objective ({c.search.objective})", out_dir / HISTORY_NAME)
    outcome = Outcome(rows, path, complete, keeper.added, skipped * per_trial)
    return SearchOutcome(outcome, best_value, dict(best.params), best_path, history,
                         len(values))


def _resume(c: Campaign, study: Any, dists: dict[str, Any], rows: list[dict[str, Any]],
            per_trial: int) -> int:
    """Tell the study every complete trial in the rows; how many there were."""
    import optuna

    by_trial: dict[int, list[dict[str, Any]]] = {}
    for r in rows:
        if r.get("trial") is not None:
            by_trial.setdefault(int(r["trial"]), []).append(r)
    told = 0
    for number in sorted(by_trial):
        trs = by_trial[number]
        if len(trs) < per_trial:
            continue
        params = {k: trs[0][k] for k in dists}
        study.add_trial(optuna.trial.create_trial(params=params, distributions=dists,
                                                  value=objective(c, trs)))
        told += 1
    return told


def write_best(c: Campaign, params: dict[str, Any], value: float, path: Path,
               trials: int) -> Path:
    """The best trial's station values over the campaign's base station file, as TOML."""
    over: dict[str, Any] = {}
    for name, v in params.items():
        if name.startswith("station."):
            set_dotted(over, name.removeprefix("station."), v)
    flight = {k: v for k, v in params.items() if k.startswith("fly.")}
    header = (f"Best of {trials} trials of campaign {c.name} ({c.path.name}): "
              f"{c.search.objective} {value:.5f} (mean over seeds {list(c.search.seeds)})\n"
              + (f"flown with {flight}\n" if flight else "")
              + "quadgcs fly --config THIS_FILE")
    config = c.base.config_path if isinstance(c.base, BaseFlight) else None  # searches fly
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(dumps(station_table(config, over), header), encoding="utf-8")
    return path
