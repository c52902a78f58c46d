"""The radiation mission's products on disk: its picture (matplotlib, off-screen) and its map
file (`map_file`), and where they are written."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from gcs.errors import UsageError
from gcs.mission.map_file import write_map
from gcs.mission.options import RunOptions
from gcs.mission.report import MissionReport
from gcs.mission.spec import MissionSpec
from planners.radiation.contour import polygon_rings
from planners.radiation.field import RadiationField


def radiation_figure(path: Path, field: RadiationField | None, products: dict[str, Any],
                     title: str) -> None:
    """True field (log colour), samples, path flown, found contour and the reference contour;
    without the truth (`field` None) the map's own mean in place of the field, and no
    reference."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    est = products["estimate"]
    ev = products["evaluation"]
    xs, ys = est.xs_m, est.ys_m
    shown = field.grid(xs, ys) if field is not None else est.mean_cps  # both [iy, ix]
    fig, ax = plt.subplots(figsize=(7.5, 7.0))
    # x north up the page, y east to the right: plot east on the horizontal axis
    mesh = ax.pcolormesh(ys, xs, np.log10(np.maximum(shown, 1e-3)).T, shading="auto",
                         cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=("true intensity" if field is not None else
                                     "mapped intensity (GP mean)") + ", log10 counts/s")
    path_xy = products["path"]
    ax.plot(path_xy[:, 1], path_xy[:, 0], "-", color="white", lw=0.7, alpha=0.8, label="path")
    s = products["samples"]
    ax.scatter(s[:, 1], s[:, 0], s=9, c="orange", edgecolors="black", linewidths=0.3,
               label=f"samples ({len(s)})", zorder=3)
    first = True
    for part in polygon_rings(est.region):
        for ring in part:
            ax.plot(ring[:, 1], ring[:, 0], "-", color="red", lw=1.6,
                    label="found contour" if first else None)
            first = False
    first = True
    ref = ev.reference if ev is not None else None
    for poly in getattr(ref, "geoms", [ref] if ref is not None else []):
        if poly.is_empty:
            continue
        x, y = poly.exterior.xy
        ax.plot(y, x, "--", color="cyan", lw=1.2, label="reference contour" if first else None)
        first = False
    if field is not None and field.sources:
        src = field.source_xy_m
        ax.scatter(src[:, 1], src[:, 0], marker="*", s=120, c="red", edgecolors="white",
                   label="sources", zorder=4)
    level = est.level_cps
    score = f"IoU {ev.iou:.2f}" if ev is not None else "unscored"
    ax.set_title(f"{title}: level {level:.0f} cps, {score}" if math.isfinite(level) else title)
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


def write_radiation_products(spec: MissionSpec, options: RunOptions, report: MissionReport,
                             products: Any) -> dict[str, str]:
    """The picture (true field or the map's mean, samples, path, found contour vs reference)
    and the map file beside it (`*.map.json`); their paths by name."""
    field, prod = products
    path = plot_path(spec, options, report.recording)
    try:
        radiation_figure(path, field, prod, title=f"{spec.name} ({report.mode.value})")
    except OSError as exc:
        raise UsageError(f"--plot {path}: cannot write ({exc.strerror or exc})") from None
    map_path = path.with_suffix(".map.json")
    try:
        write_map(map_path, prod["estimate"], prod["samples"],
                  "truth" if field is not None else "none")
    except OSError as exc:
        raise UsageError(f"{map_path}: cannot write ({exc.strerror or exc})") from None
    return {"plot": str(path), "map": str(map_path)}
