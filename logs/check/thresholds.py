"""The checks' thresholds: one table, each with its unit, which side is worse, and why it matters.

A value at or beyond `fail` is FAIL, at or beyond `warn` is WARN, else PASS; a check whose data
the recording lacks is SKIP. `worse` says which way is bad ("high": larger is worse, "low":
smaller is worse). A TOML file overrides any of them (`quadgcs logs check --thresholds FILE`):

    ["link.loss_pct"]
    warn = 1.0
    fail = 5.0

Defaults are set from what the bundled SITL flies cleanly on both firmware profiles (a clean
lockstep hold passes every one), from the real ArduCopter fixture logs, and from ArduPilot's
own guidance where it has some (vibration, battery sag).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any


class ThresholdError(ValueError):
    """A thresholds file that cannot be used (its message is one line for the user)."""


@dataclass(frozen=True, slots=True)
class Threshold:
    """One check's limits."""

    key: str  # "group.metric"
    unit: str
    warn: float
    fail: float
    worse: str  # "high" or "low"
    why: str

    @property
    def group(self) -> str:
        return self.key.split(".", 1)[0]


def _t(key: str, unit: str, warn: float, fail: float, worse: str, why: str) -> Threshold:
    return Threshold(key, unit, warn, fail, worse, why)


DEFAULTS: tuple[Threshold, ...] = (
    _t("link.loss_pct", "%", 2.0, 10.0, "high",
       "frames lost (sequence gaps) starve the estimator of sonar and IMU and the supervisor "
       "of proof of life"),
    _t("link.gaps", "count", 1, 5, "high",
       "silences over 0.3 s: the estimator coasts on the IMU alone through each"),
    _t("link.longest_silence_s", "s", 0.5, 1.5, "high",
       "the longest time nothing came from the vehicle; past 1.5 s the station lands it blind"),
    _t("link.stream_rate_pct", "%", 55.0, 30.0, "low",
       "the slowest asked-for stream as delivered, against the rate asked: a stream slower "
       "than planned leaves the 25 ms loop without fresh readings (3.2.1 sends at most "
       "2/3 of what is asked: 16.7 Hz for 25 Hz)"),
    _t("loop.jitter_p99_ms", "ms", 2.0, 5.0, "high",
       "the PC loop's period error, 99th percentile: the controller's dt assumes 25 ms"),
    _t("loop.overruns_pct", "%", 0.1, 1.0, "high",
       "ticks that took longer than their period or woke a whole period late: missed commands"),
    _t("loop.late_ticks_pct", "%", 0.5, 2.0, "high",
       "ticks that woke more than half a period late: stale sticks on the vehicle"),
    _t("estimator.innovation_rms_m", "m", 0.08, 0.2, "high",
       "sonar minus prediction: large innovations mean a model or sensor the estimator "
       "does not believe"),
    _t("estimator.rejected_pct", "%", 25.0, 40.0, "high",
       "sonar readings the gate refused: the hold then flies on the accelerometer"),
    _t("estimator.vs_reference_rms_m", "m", 0.12, 0.25, "high",
       "the altitude estimate against ground truth or motion capture: what the controller "
       "believed against where the vehicle was"),
    _t("vibration.acc_rms_x_mps2", "m/s²", 1.5, 3.0, "high",
       "accelerometer noise about its 1 s mean while flying, forward axis"),
    _t("vibration.acc_rms_y_mps2", "m/s²", 1.5, 3.0, "high",
       "accelerometer noise about its 1 s mean while flying, right axis"),
    _t("vibration.acc_rms_z_mps2", "m/s²", 1.5, 3.0, "high",
       "accelerometer noise about its 1 s mean while flying, down axis: the altitude "
       "estimator integrates this one"),
    _t("vibration.worst_throttle_band_mps2", "m/s²", 3.0, 5.0, "high",
       "the noisiest throttle band (25 % bands): vibration that grows with throttle is a "
       "prop or motor"),
    _t("control.stick_limit_pct", "%", 2.0, 10.0, "high",
       "time the throttle sat at its limit in the air: the controller had no authority left"),
    _t("control.integrator_limit_pct", "%", 2.0, 10.0, "high",
       "time the altitude integrator sat at its limit: a trim it could not find"),
    _t("control.hover_drift_pct", "% thr", 8.0, 15.0, "high",
       "how far the learned hover throttle moved while flying: a draining battery or a "
       "changing load"),
    _t("power.sag_v_per_a", "V/A", 0.06, 0.12, "high",
       "voltage drop per ampere drawn (the pack's resistance): a tired pack browns out on a "
       "climb"),
    _t("power.min_cell_v", "V", 3.5, 3.3, "low",
       "the lowest per-cell voltage under load: below 3.3 V the autopilot may brown out"),
    _t("events.failsafes", "count", 1, 1, "high",
       "the vehicle's or the station's failsafe acted: the flight did not end as commanded"),
    _t("events.unasked_modes", "count", 1, 3, "high",
       "mode changes the ground station did not ask for"),
    _t("events.refusals", "count", 1, 5, "high",
       "commands the vehicle refused (COMMAND_ACK not accepted) and never accepted later"),
    _t("hold.rms_m", "m", 0.12, 0.25, "high",
       "the PC altitude hold's error against its setpoint, RMS (source named: truth, "
       "estimate or none)"),
    _t("hold.bias_m", "m", 0.08, 0.15, "high",
       "the hold's mean error, absolute: a constant offset"),
    _t("hold.std_m", "m", 0.1, 0.2, "high",
       "the hold's spread about its mean: wandering"),
    _t("hold.error_memory_s", "s", 1.0, 2.0, "high",
       "how long a hold error lasts (its autocorrelation falls to 1/e): a soft hold, low "
       "gains or a weak vehicle, lets each disturbance linger"),
)


def defaults() -> dict[str, Threshold]:
    """The table, by key."""
    return {t.key: t for t in DEFAULTS}


def _number(path: Path, key: str, name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ThresholdError(f"{path}: [{key!r}] {name} = {value!r}: expected a finite number")
    return float(value)


def apply_overrides(table: Mapping[str, Threshold], data: Mapping[str, Any],
                    path: Path) -> dict[str, Threshold]:
    """`table` with the parsed TOML `data`'s warn/fail values put in."""
    out = dict(table)
    for key, entry in data.items():
        if key not in out:
            raise ThresholdError(f"{path}: unknown check {key!r}; expected one of "
                                 f"{', '.join(sorted(out))}")
        if not isinstance(entry, Mapping):
            raise ThresholdError(f"{path}: [{key!r}] must be a table with warn and/or fail")
        unknown = sorted(set(entry) - {"warn", "fail"})
        if unknown:
            raise ThresholdError(f"{path}: [{key!r}] unknown key {unknown[0]!r}; expected "
                                 "warn or fail")
        base = out[key]
        warn = _number(path, key, "warn", entry.get("warn", base.warn))
        fail = _number(path, key, "fail", entry.get("fail", base.fail))
        if (base.worse == "high" and fail < warn) or (base.worse == "low" and fail > warn):
            side = "at or above" if base.worse == "high" else "at or below"
            raise ThresholdError(f"{path}: [{key!r}] fail {fail:g} must be {side} warn "
                                 f"{warn:g} (worse is {base.worse})")
        out[key] = dataclasses.replace(base, warn=warn, fail=fail)
    return out


def load_thresholds(path: Path | None) -> dict[str, Threshold]:
    """The default table, overridden by the TOML file at `path` (None: defaults)."""
    table = defaults()
    if path is None:
        return table
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError as exc:
        raise ThresholdError(f"{path}: no such file (expected a thresholds TOML)") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise ThresholdError(f"{path}: cannot read: {exc}") from exc
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ThresholdError(f"{path}: not valid TOML: {exc}") from exc
    return apply_overrides(table, data, path)
