"""Pictures of a campaign: a metric against each axis, a heat map for two, a search's history.

matplotlib is the project's optional plotting dependency (`quadgcs[plot]`, in `dev`); without
it the campaign still writes its results and says that no pictures were drawn.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lab.campaign.metrics import OK


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _label(v: Any) -> str:
    return Path(v).stem if isinstance(v, str) and v.endswith(".toml") else str(v)


def _metric(rows: Sequence[dict[str, Any]], metric: str) -> list[dict[str, Any]]:
    return [r for r in rows if r.get("status") == OK
            and math.isfinite(float(r.get(metric, math.nan)))]


def axis_plots(rows: Sequence[dict[str, Any]], axes: Sequence[str], metric: str,
               out_dir: Path) -> list[Path] | None:
    """PNGs of `metric` against every axis but the seed (and a heat map when there are two);
    None when matplotlib is missing."""
    plt = _pyplot()
    if plt is None:
        return None
    ok = _metric(rows, metric)
    shown = [a for a in axes if a != "seed"] or ["seed"]
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for axis in shown:
        values = sorted({r.get(axis) for r in ok}, key=lambda v: (str(type(v)), v))
        numeric = all(isinstance(v, int | float) for v in values)
        fig, ax = plt.subplots(figsize=(6, 4))
        xs = [r[axis] if numeric else values.index(r[axis]) for r in ok]
        ax.scatter(xs, [r[metric] for r in ok], s=10, alpha=0.5, label="runs")
        meds = [float(np.median([r[metric] for r in ok if r[axis] == v])) for v in values]
        ax.plot(values if numeric else range(len(values)), meds, "o-", color="C3",
                label="median")
        if not numeric:
            ax.set_xticks(range(len(values)), [_label(v) for v in values])
        ax.set_xlabel(axis)
        ax.set_ylabel(metric)
        ax.legend()
        ax.grid(alpha=0.3)
        path = out_dir / f"{metric}_vs_{axis}.png"
        fig.tight_layout()
        fig.savefig(path, dpi=100)
        plt.close(fig)
        paths.append(path)
    if len(shown) == 2:
        paths.append(_heat_map(plt, ok, shown, metric, out_dir))
    return paths


def _heat_map(plt: Any, ok: Sequence[dict[str, Any]], axes: Sequence[str], metric: str,
              out_dir: Path) -> Path:
    a, b = axes
    xs = sorted({r[a] for r in ok}, key=str)
    ys = sorted({r[b] for r in ok}, key=str)
    grid = np.full((len(ys), len(xs)), np.nan)
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            vals = [r[metric] for r in ok if r[a] == x and r[b] == y]
            if vals:
                grid[i, j] = float(np.median(vals))
    fig, ax = plt.subplots(figsize=(6, 4.5))
    im = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis")
    ax.set_xticks(range(len(xs)), [_label(x) for x in xs])
    ax.set_yticks(range(len(ys)), [_label(y) for y in ys])
    ax.set_xlabel(a)
    ax.set_ylabel(b)
    fig.colorbar(im, ax=ax, label=f"median {metric}")
    path = out_dir / f"{metric}_heatmap.png"
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def history_plot(objective: Sequence[float], name: str, out: Path) -> Path | None:
    """A search's objective per trial and the best so far; None without matplotlib."""
    plt = _pyplot()
    if plt is None:
        return None
    vals = np.asarray(objective, dtype=float)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(range(len(vals)), vals, "o", label="trial")
    ax.plot(range(len(vals)), np.minimum.accumulate(vals), "-", color="C3", label="best so far")
    ax.set_xlabel("trial")
    ax.set_ylabel(name)
    ax.legend()
    ax.grid(alpha=0.3)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out
