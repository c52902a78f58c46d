"""A fault-search campaign from start to finish: a clean flight to learn the flight's length, the
search on Ray (or in this process), every run a row of results.parquet, each violated property's
worst run shrunk and written as a schedule file with the one command that replays it, a summary
table and a PNG of the margins over the search.
"""

from __future__ import annotations

import math
import shlex
import sys
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from lab.campaign.pool import run_all
from lab.campaign.run import RunSpec
from lab.faultsearch.runner import SearchFlight, fly_schedule
from lab.faultsearch.schedule import Schedule, dumps, load_schedule
from lab.faultsearch.search import Executor, SearchOptions, in_process, run_params, search
from lab.faultsearch.space import Space, shrink
from lab.faultsearch.spec import FaultCampaign

RESULTS = "results.parquet"
PLOT = "margins.png"


@dataclass(frozen=True, slots=True)
class Violation:
    """A violated property's worst run, shrunk, and how to replay it."""

    prop: str
    run: int
    seed: int
    margin: float
    count: int  # runs that violated it
    first_run: int
    schedule: Path
    command: str
    note: str


def ray_run(flight: SearchFlight, run: RunSpec, space: Space) -> dict[str, Any]:
    """A Ray task: one run of the search."""
    values = dict(run.values)
    number = int(values.pop("run"))
    return run_params(flight, space, number, values)


def ray_executor(ray: Any) -> Executor:
    """Fly each batch as Ray tasks (rows back in the batch's order)."""
    def execute(flight: SearchFlight, space: Space,
                batch: Sequence[tuple[int, dict[str, Any]]]) -> list[dict[str, Any]]:
        got: dict[int, dict[str, Any]] = {}
        runs = [RunSpec(f"run{n}", {**p, "run": n}) for n, p in batch]

        def keep(row: dict[str, Any]) -> None:
            n = int(row.get("run", 0))
            row.setdefault("margin", math.inf)
            got[n] = row
        if not run_all(ray, ray_run, runs, (flight, space), keep):
            raise KeyboardInterrupt
        return [got.get(n, {"run": n, "margin": math.inf}) for n, _ in batch]
    return execute


def _pool_run(args: tuple[SearchFlight, Space, int, dict[str, Any]]) -> dict[str, Any]:
    return run_params(*args)


def pool_executor(pool: Any) -> Executor:
    """Fly each batch on a `multiprocessing` pool (its processes reused from run to run)."""
    def execute(flight: SearchFlight, space: Space,
                batch: Sequence[tuple[int, dict[str, Any]]]) -> list[dict[str, Any]]:
        return list(pool.map(_pool_run, [(flight, space, n, p) for n, p in batch]))
    return execute


def command(flight: SearchFlight, seed: int, schedule: Path, world: str | None = None) -> str:
    """The one line that replays a run: `quadgcs fly --lockstep` with the search's flight."""
    p = flight.plan
    args = ["quadgcs", "fly", "--lockstep", "--profile", flight.profile, "--seed", str(seed),
            "--alt", f"{p.alt_m:g}", "--hold", f"{p.hold_s:g}"]
    if p.step_m:
        args += ["--step", f"{p.step_m:g}", "--step-watch", f"{p.step_observe_s:g}"]
    if flight.world is not None:
        args += ["--world", world or str(flight.world)]
    if flight.fix_failsafe:
        args.append("--fix-failsafe")
    return shlex.join([*args, "--faults", str(schedule)])


def flight_span(flight: SearchFlight, seed: int) -> float:
    """How long a clean flight lasts (the whole flight a fault may fall in)."""
    r = fly_schedule(flight, seed, Schedule())
    return math.ceil(r.sim_s)


def violations(rows: list[dict[str, Any]], flight: SearchFlight, out_dir: Path,
               shrink_runs: int, world: str | None = None) -> list[Violation]:
    """Each violated property's worst run, shrunk (`shrink_runs` flights at most) and
    written to out_dir/violations/PROPERTY.toml."""
    by_prop: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        for name in str(r.get("violated") or "").split(","):
            if name:
                by_prop.setdefault(name, []).append(r)
    found = []
    for prop, rs in sorted(by_prop.items()):
        worst = min(rs, key=lambda r: float(r.get(f"margin.{prop}", r["margin"])))
        seed = int(worst["seed"])
        tmp = out_dir / "violations" / f"{prop}.full.toml"
        tmp.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(str(worst["schedule"]) + "\n", encoding="utf-8")
        schedule = load_schedule(tmp)

        def still(s: Schedule, prop: str = prop, seed: int = seed) -> bool:
            return any(m.name == prop for m in fly_schedule(flight, seed, s).violated)
        small, _ = shrink(schedule, still, shrink_runs) if shrink_runs else (schedule, 0)
        path = out_dir / "violations" / f"{prop}.toml"
        cmd = command(flight, seed, path, world)
        note = worst.get(f"note.{prop}", worst.get("note", ""))
        path.write_text(dumps(small, f"{prop} violated (run {worst['run']}, seed {seed}): "
                              f"{note}\n{cmd}"), encoding="utf-8")
        found.append(Violation(prop, int(worst["run"]), seed,
                               float(worst.get(f"margin.{prop}", worst["margin"])), len(rs),
                               min(int(r["run"]) for r in rs), path, cmd,
                               str(worst.get(f"note.{prop}", worst.get("note", "")))))
    return found


def write_rows(path: Path, rows: list[dict[str, Any]]) -> None:
    """Every row to Parquet (strings where a column mixes types)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols = sorted({k for r in rows for k in r}, key=lambda c: (c.startswith(("p.", "margin.")),
                                                                c not in ("run", "seed"), c))
    arrays = {}
    for c in cols:
        vals = [r.get(c) for r in rows]
        if all((isinstance(v, int | float) and not isinstance(v, bool)) or v is None
               for v in vals):
            arrays[c] = pa.array([math.nan if v is None else float(v) for v in vals])
        else:
            arrays[c] = pa.array([None if v is None else str(v) for v in vals], pa.string())
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.table(arrays), path)


def margins_plot(rows: list[dict[str, Any]], out: Path) -> Path | None:
    """Each run's smallest margin over the search, by property; None without matplotlib."""
    from lab.campaign.plots import _pyplot

    plt = _pyplot()
    if plt is None:
        return None
    fig, ax = plt.subplots(figsize=(8, 4.5))
    props = sorted({str(r["property"]) for r in rows})
    for i, prop in enumerate(props):
        pts = [(int(r["run"]), float(r["margin"])) for r in rows if r["property"] == prop
               and math.isfinite(float(r["margin"]))]
        if pts:
            ax.plot([p[0] for p in pts], [max(p[1], -3.0) for p in pts], ".", color=f"C{i}",
                    label=prop, alpha=0.7)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("run")
    ax.set_ylabel("smallest margin (clipped at -3)")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def summary_table(rows: list[dict[str, Any]], found: list[Violation]) -> str:
    """Per property: runs it was the closest in, its smallest margin, violations."""
    lines = [f"{'property':12s} {'closest in':>10s} {'min margin':>11s} {'violated':>9s} "
             f"{'first at':>9s}"]
    byp = {v.prop: v for v in found}
    for prop in sorted({str(r["property"]) for r in rows}):
        rs = [r for r in rows if r["property"] == prop]
        m = min(float(r["margin"]) for r in rs)
        v = byp.get(prop)
        lines.append(f"{prop:12s} {len(rs):10d} {m:11.3f} {v.count if v else 0:9d} "
                     f"{v.first_run if v else '-':>9}")
    for prop, v in byp.items():
        if prop not in {r["property"] for r in rows}:
            lines.append(f"{prop:12s} {0:10d} {v.margin:11.3f} {v.count:9d} {v.first_run:>9}")
    return "\n".join(lines)


def run_fault_campaign(c: FaultCampaign, out_dir: Path, ray: Any | None = None,
                       workers: int = 1, quiet: bool = False,
                       execute: Executor | None = None) -> tuple[list[dict[str, Any]],
                                                                 list[Violation]]:
    """The whole campaign; its rows and violations (files in `out_dir`). Runs on Ray when
    given, else on `execute` (default: in this process)."""
    span = flight_span(c.flight, c.space.seeds[0])
    space = replace(c.space, span_s=span)
    opts = SearchOptions(runs=c.runs, random_runs=c.random_runs, sample_seed=c.sample_seed,
                         batch=max(1, workers))
    if ray is not None:
        execute = ray_executor(ray)
    elif execute is None:
        execute = in_process
    rows: list[dict[str, Any]] = []

    def keep(row: dict[str, Any]) -> None:
        rows.append(row)
        if not quiet:
            bad = sum(bool(r.get("violated")) for r in rows)
            print(f"\r{c.name}: {len(rows)}/{c.runs} runs, {bad} violating", end="",
                  file=sys.stderr, flush=True)
    try:
        search(c.flight, space, opts, execute, on_row=keep)
    except KeyboardInterrupt:
        pass
    finally:
        if not quiet:
            print(file=sys.stderr)
        write_rows(out_dir / RESULTS, rows)
    found = violations(rows, c.flight, out_dir, c.shrink_runs, c.world)
    return rows, found
