"""The runs a campaign asks for: every combination of a grid's axes, or a seeded random sample."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from lab.campaign.run import RunSpec, make_run
from lab.campaign.types import Campaign, Range


def draw(axis: Range | tuple[Any, ...], rng: np.random.Generator) -> Any:
    """One value of a random axis."""
    if isinstance(axis, Range):
        if axis.integer:
            return int(rng.integers(int(axis.lo), int(axis.hi) + 1))
        if axis.log:
            return float(math.exp(rng.uniform(math.log(axis.lo), math.log(axis.hi))))
        return float(rng.uniform(axis.lo, axis.hi))
    return axis[int(rng.integers(len(axis)))]


def plan_runs(c: Campaign) -> list[RunSpec]:
    """The campaign's runs in a stable order (the same file always plans the same runs)."""
    names = list(c.axes)
    if c.kind == "grid":
        grids = [c.axes[n] for n in names]
        combos = itertools.product(*grids)  # type: ignore[arg-type]  # grid axes are tuples
        return [make_run(c.base, dict(zip(names, combo, strict=True))) for combo in combos]
    if c.kind == "random":
        rng = np.random.default_rng(c.sample_seed)
        return [make_run(c.base, {n: draw(c.axes[n], rng) for n in names})
                for _ in range(c.samples)]
    raise ValueError(f"kind {c.kind!r} plans its runs as it goes (lab.campaign.search)")
