"""The check report as one self-contained HTML page: each group's checks beside the plot a
reviewer needs to judge them, drawn as inline SVG (no plotting library, no external files)."""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from logs.check.against import Placement
from logs.check.metrics_link import reference_alt
from logs.check.result import CheckResult, Status
from logs.check.series import FlightSeries

Line = tuple[str, np.ndarray, np.ndarray]  # label, t (s), y
Page = tuple[str, FlightSeries, list[CheckResult], Sequence[Placement] | None]
COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd")
STATUS_COLORS = {Status.PASS: "#2ca02c", Status.WARN: "#ff7f0e", Status.FAIL: "#d62728",
                 Status.SKIP: "#999999"}
W, H, PAD = 640, 200, 40
MAX_POINTS = 1500


def svg_plot(title: str, unit: str, lines: Sequence[Line]) -> str:
    """A line chart of the given series against time."""
    lines = [(n, t, y) for n, t, y in lines if t.size and np.isfinite(y).any()]
    if not lines:
        return f"<p><em>{html.escape(title)}: no data</em></p>"
    t_all = np.concatenate([t for _n, t, _y in lines])
    y_all = np.concatenate([y[np.isfinite(y)] for _n, _t, y in lines])
    t0, t1 = float(t_all.min()), float(t_all.max())
    y0, y1 = float(y_all.min()), float(y_all.max())
    if t1 <= t0:
        t1 = t0 + 1.0
    if y1 <= y0:
        y0, y1 = y0 - 0.5, y1 + 0.5

    def px(t: np.ndarray, y: np.ndarray) -> str:
        x = PAD + (t - t0) / (t1 - t0) * (W - 2 * PAD)
        yy = H - PAD + (y0 - y) / (y1 - y0) * (H - 2 * PAD)
        return " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(x, yy, strict=True)
                        if math.isfinite(b))

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
             f'style="background:#fff;border:1px solid #ccc">',
             f'<text x="{PAD}" y="14" font-size="12">{html.escape(title)} ({html.escape(unit)})'
             '</text>',
             f'<text x="2" y="{PAD}" font-size="10">{y1:.3g}</text>',
             f'<text x="2" y="{H - PAD}" font-size="10">{y0:.3g}</text>',
             f'<text x="{PAD}" y="{H - 8}" font-size="10">{t0:.1f} s</text>',
             f'<text x="{W - PAD - 30}" y="{H - 8}" font-size="10">{t1:.1f} s</text>']
    for i, (name, t, y) in enumerate(lines):
        step = max(1, t.size // MAX_POINTS)
        color = COLORS[i % len(COLORS)]
        parts.append(f'<polyline fill="none" stroke="{color}" stroke-width="1" '
                     f'points="{px(t[::step], y[::step])}"/>')
        parts.append(f'<text x="{W - PAD - 150}" y="{14 + 12 * i}" font-size="10" '
                     f'fill="{color}">{html.escape(name)}</text>')
    parts.append("</svg>")
    return "".join(parts)


def _rate(times: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(times)
    if not t.size:
        return t, t
    edges = np.arange(math.floor(t.min()), math.ceil(t.max()) + 1.0)
    counts, _ = np.histogram(t, edges) if edges.size > 1 else (np.array([t.size]), edges)
    return edges[:-1], counts.astype(float)


def group_plots(fs: FlightSeries) -> dict[str, str]:
    """The plot of each check group."""
    c, est, lp, imu, b, hb = fs.control, fs.estimate, fs.loop, fs.imu, fs.battery, fs.heartbeat
    ref, source = reference_alt(fs)
    alt_lines: list[Line] = [("setpoint", c["t"], c["setpoint"]),
                             ("estimate", est["t"], est["alt"])]
    if ref is not None:
        alt_lines.append((source, ref[0], ref[1]))
    return {
        "link": svg_plot("frames received per second", "1/s", [("rx", *_rate(fs.rx_times))]),
        "loop": svg_plot("loop timing", "ms", [("jitter", lp["t"], lp["jitter_ms"]),
                                               ("lateness", lp["t"], lp["lateness_ms"]),
                                               ("compute", lp["t"], lp["compute_ms"])]),
        "estimator": svg_plot("sonar innovation", "m", [("innovation", est["t"][est["used"] > 0.5],
                                                         est["innovation"][est["used"] > 0.5])]),
        "vibration": svg_plot("accelerometer", "m/s²", [("x", imu["t"], imu["ax"]),
                                                        ("y", imu["t"], imu["ay"]),
                                                        ("z + g", imu["t"], imu["az"] + 9.80665)]),
        "control": svg_plot("throttle", "µs", [("controller", c["t"], c["throttle_us"]),
                                               ("override sent", fs.tx_overrides["t"],
                                                fs.tx_overrides["throttle_us"])]),
        "power": svg_plot("battery", "V, A", [("volts", b["t"], b["volt"]),
                                              ("amperes", b["t"], b["amp"])]),
        "events": svg_plot("flight mode (custom_mode) and armed", "", [
            ("mode", hb["t"], hb["mode"]), ("armed", hb["t"], hb["armed"])]),
        "hold": svg_plot("altitude", "m", alt_lines),
    }


def _row(r: CheckResult) -> str:
    value = "-" if math.isnan(r.value) else f"{r.value:.4g} {r.threshold.unit}"
    t = r.threshold
    sign = "≥" if t.worse == "high" else "≤"
    return (f'<tr><td style="color:{STATUS_COLORS[r.status]}"><b>{r.status.value}</b></td>'
            f"<td>{html.escape(r.key)}</td><td>{html.escape(value)}</td>"
            f"<td>warn {sign} {t.warn:g}, fail {sign} {t.fail:g}</td>"
            f"<td>{html.escape(r.detail)}{' [' + html.escape(r.source) + ']' if r.source else ''}"
            f"<br><small>{html.escape(t.why)}</small></td></tr>")


def page_html(name: str, fs: FlightSeries, results: list[CheckResult],
              placements: Sequence[Placement] | None) -> str:
    """One recording's section."""
    plots = group_plots(fs)
    parts = [f"<h2>{html.escape(name)}</h2>"]
    groups: dict[str, list[CheckResult]] = {}
    for r in results:
        groups.setdefault(r.threshold.group, []).append(r)
    for group, rows in groups.items():
        parts.append(f"<h3>{html.escape(group)}</h3><div style='display:flex;gap:1em'>"
                     "<table border='1' cellpadding='3' style='border-collapse:collapse;"
                     "font-size:12px;max-width:640px'>"
                     + "".join(_row(r) for r in rows) + "</table>"
                     + plots.get(group, "") + "</div>")
    if placements:
        parts.append("<h3>against the campaign</h3><table border='1' cellpadding='3'>"
                     "<tr><th></th><th>metric</th><th>value</th><th>percentile</th>"
                     "<th>campaign best / median / worst</th></tr>")
        for p in placements:
            mark = "<b style='color:#d62728'>BEYOND</b>" if p.flagged else "within"
            parts.append(f"<tr><td>{mark}</td><td>{html.escape(p.key)}</td>"
                         f"<td>{p.value:.4g}</td><td>{p.percentile:.1f}</td>"
                         f"<td>{p.campaign_best:.4g} / {p.campaign_median:.4g} / "
                         f"{p.campaign_worst:.4g} ({p.runs} runs)</td></tr>")
        parts.append("</table>")
    return "".join(parts)


def write_html(out: Path, pages: Sequence[Page]) -> Path:
    """Write the report of every page to `out`."""
    body = "".join(page_html(*p) for p in pages)
    out.write_text("<!doctype html><html><head><meta charset='utf-8'><title>quadgcs logs check"
                   "</title></head><body style='font-family:sans-serif'>"
                   f"<h1>quadgcs logs check</h1>{body}</body></html>", encoding="utf-8")
    return out
