"""The radiation mission's picture (matplotlib, off-screen) and where it is written."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from gcs.errors import UsageError
from gcs.mission.options import RunOptions
from gcs.mission.report import MissionReport
from gcs.mission.spec import MissionSpec
from planners.radiation_field import RadiationField


def radiation_figure(path: Path, field: RadiationField, products: dict[str, Any],
                     title: str) -> None:
    """True field (log colour), samples, path flown, found contour and the reference contour."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    est = products["estimate"]
    ev = products["evaluation"]
    xs, ys = est.xs_m, est.ys_m
    truth = field.grid(xs, ys)
    fig, ax = plt.subplots(figsize=(7.5, 7.0))
    # x north up the page, y east to the right: plot east on the horizontal axis
    mesh = ax.pcolormesh(ys, xs, np.log10(truth).T, shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="true intensity, log10 counts/s")
    path_xy = products["path"]
    ax.plot(path_xy[:, 1], path_xy[:, 0], "-", color="white", lw=0.7, alpha=0.8, label="path")
    s = products["samples"]
    ax.scatter(s[:, 1], s[:, 0], s=9, c="orange", edgecolors="black", linewidths=0.3,
               label=f"samples ({len(s)})", zorder=3)
    first = True
    for part in ev.polygons:
        for ring in part:
            ax.plot(ring[:, 1], ring[:, 0], "-", color="red", lw=1.6,
                    label="found contour" if first else None)
            first = False
    first = True
    ref = ev.reference
    for poly in getattr(ref, "geoms", [ref]):
        if poly.is_empty:
            continue
        x, y = poly.exterior.xy
        ax.plot(y, x, "--", color="cyan", lw=1.2, label="reference contour" if first else None)
        first = False
    src = field.source_xy_m
    ax.scatter(src[:, 1], src[:, 0], marker="*", s=120, c="red", edgecolors="white",
               label="sources", zorder=4)
    level = est.level_cps
    ax.set_title(f"{title}: level {level:.0f} cps, IoU {ev.iou:.2f}"
                 if math.isfinite(level) else title)
    ax.set_xlabel("east, m")
    ax.set_ylabel("north, m")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=7)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_path(spec: MissionSpec, options: RunOptions, recording: str | None) -> Path:
    """`--plot PATH`, else next to the recording, else in the output directory."""
    if options.plot is not None:
        return options.plot
    if recording is not None:
        return Path(recording).with_suffix(".png")
    out = options.output if options.output.suffix != ".mcap" else options.output.parent
    return out / f"{spec.name}.png"


def write_radiation_plot(spec: MissionSpec, options: RunOptions, report: MissionReport,
                         products: Any) -> str:
    """The picture: true field, samples, path, found contour vs reference contour."""
    field, prod = products
    path = plot_path(spec, options, report.recording)
    try:
        radiation_figure(path, field, prod, title=f"{spec.name} ({report.mode.value})")
    except OSError as exc:
        raise UsageError(f"--plot {path}: cannot write ({exc.strerror or exc})") from None
    return str(path)
