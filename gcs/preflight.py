"""Pre-flight checks: the vehicle's parameters must make the station's link-loss policy safe.

The station lands a vehicle it cannot hear and then falls silent, so the autopilot's own GCS
failsafe must be on, and on ArduCopter 4.x it must act before the RC overrides lapse
(`RC_OVERRIDE_TIME`), or the throttle falls to the radio's minimum. The station also assumes the
throttle on channel 3 spanning 1000..2000 µs, sticks on channels 1–4, and a battery above its
failsafe. `evaluate` is pure; `read_and_check` reads the parameters over the link and, with the
pilot's consent, sets the failsafe parameters (read back by the link).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from firmware_link.records import Dialect

RC_SPAN_TOLERANCE_US = 50
BATTERY_MARGIN_V = 0.2
# 4.x FS_GCS_ENABLE 5 = LAND; 3.2.1 has no LAND option, 1 = RTL, which lands without GPS
GCS_FAILSAFE_ON = {Dialect.APM25: 1.0, Dialect.COPTER4: 5.0}
FS_GCS_TIMEOUT_MIN_S = 2.0  # the firmware's lower bound
CHANNEL_MAP = {"RCMAP_ROLL": 1.0, "RCMAP_PITCH": 2.0, "RCMAP_THROTTLE": 3.0, "RCMAP_YAW": 4.0}


@dataclass(frozen=True, slots=True)
class Check:
    """One pre-flight check and what would fix it (parameter → value), if anything can."""

    name: str
    ok: bool
    detail: str
    fix: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class PreflightReport:
    """Every check, in order."""

    dialect: Dialect
    checks: tuple[Check, ...]

    @property
    def ok(self) -> bool:
        """All checks passed."""
        return all(c.ok for c in self.checks)

    @property
    def fixes(self) -> dict[str, float]:
        """The parameter changes that would make the failing checks pass."""
        out: dict[str, float] = {}
        for c in self.checks:
            if not c.ok:
                out.update(c.fix)
        return out

    def summary(self) -> str:
        """One line: what failed (and how to fix it), or what passed."""
        bad = [c for c in self.checks if not c.ok]
        if not bad:
            return "; ".join(c.detail for c in self.checks)
        return "; ".join(f"{c.name}: {c.detail}" for c in bad)


def required_parameters(dialect: Dialect) -> tuple[str, ...]:
    """What `evaluate` reads for this firmware."""
    names = ["FS_GCS_ENABLE", "RC3_MIN", "RC3_MAX", "RC3_TRIM", *CHANNEL_MAP]
    if dialect is Dialect.COPTER4:
        names += ["FS_GCS_TIMEOUT", "RC_OVERRIDE_TIME", "BATT_LOW_VOLT"]
    else:
        names += ["FS_BATT_VOLTAGE"]
    return tuple(names)


def evaluate(dialect: Dialect, params: Mapping[str, float], battery_v: float | None,
             unreadable: Mapping[str, str] | None = None) -> PreflightReport:
    """Judge the parameters (`unreadable`: name → why it could not be read)."""
    missing = dict(unreadable or {})

    def get(name: str) -> float | None:
        return params.get(name) if name not in missing else None

    checks = [_gcs_failsafe(dialect, get, missing)]
    if dialect is Dialect.COPTER4:
        checks.append(_override_lapse(get, missing))
    checks.append(_throttle_range(get, missing))
    checks.append(_channel_map(get, missing))
    checks.append(_battery(dialect, get, battery_v))
    return PreflightReport(dialect, tuple(checks))


def _unreadable(name: str, missing: Mapping[str, str]) -> str:
    return f"could not read {name} ({missing.get(name, 'not reported')})"


def _gcs_failsafe(dialect: Dialect, get: Callable[[str], float | None],
                  missing: Mapping[str, str]) -> Check:
    v = get("FS_GCS_ENABLE")
    if v is None:
        return Check("GCS failsafe", False, _unreadable("FS_GCS_ENABLE", missing))
    on = GCS_FAILSAFE_ON.get(dialect, 1.0)
    if v == 0:
        return Check("GCS failsafe", False, "FS_GCS_ENABLE is 0: a lost link would leave the "
                     f"vehicle with no failsafe (set FS_GCS_ENABLE {on:g})", {"FS_GCS_ENABLE": on})
    return Check("GCS failsafe", True, f"FS_GCS_ENABLE {v:g}")


def _override_lapse(get: Callable[[str], float | None], missing: Mapping[str, str]) -> Check:
    timeout, lapse = get("FS_GCS_TIMEOUT"), get("RC_OVERRIDE_TIME")
    for name, v in (("FS_GCS_TIMEOUT", timeout), ("RC_OVERRIDE_TIME", lapse)):
        if v is None:
            return Check("failsafe before overrides lapse", False, _unreadable(name, missing))
    assert timeout is not None and lapse is not None
    if lapse == 0:
        return Check("failsafe before overrides lapse", False,
                     "RC_OVERRIDE_TIME is 0: the vehicle ignores RC overrides")
    if lapse < 0:  # overrides never lapse: the GCS failsafe alone decides
        return Check("failsafe before overrides lapse", True, "RC_OVERRIDE_TIME never lapses")
    if timeout < lapse:
        return Check("failsafe before overrides lapse", True,
                     f"FS_GCS_TIMEOUT {timeout:g} s < RC_OVERRIDE_TIME {lapse:g} s")
    want = max(FS_GCS_TIMEOUT_MIN_S, math.floor(lapse) - 1.0)
    fix = {"FS_GCS_TIMEOUT": want} if want < lapse else {}
    return Check("failsafe before overrides lapse", False,
                 f"FS_GCS_TIMEOUT {timeout:g} s is not shorter than RC_OVERRIDE_TIME {lapse:g} s: "
                 "the throttle would fall to the radio's minimum before the failsafe lands the "
                 f"vehicle" + (f" (set FS_GCS_TIMEOUT {want:g})" if fix else ""), fix)


def _throttle_range(get: Callable[[str], float | None], missing: Mapping[str, str]) -> Check:
    lo, hi = get("RC3_MIN"), get("RC3_MAX")
    for name, v in (("RC3_MIN", lo), ("RC3_MAX", hi)):
        if v is None:
            return Check("throttle range", False, _unreadable(name, missing))
    assert lo is not None and hi is not None
    if abs(lo - 1000) > RC_SPAN_TOLERANCE_US or abs(hi - 2000) > RC_SPAN_TOLERANCE_US:
        return Check("throttle range", False, f"RC3_MIN/MAX {lo:g}/{hi:g} us: the station's "
                     "throttle curve assumes 1000/2000 us (calibrate the radio or the config)")
    return Check("throttle range", True, f"RC3 {lo:g}..{hi:g} us")


def _channel_map(get: Callable[[str], float | None], missing: Mapping[str, str]) -> Check:
    wrong = []
    for name, want in CHANNEL_MAP.items():
        v = get(name)
        if v is None:
            return Check("channel map", False, _unreadable(name, missing))
        if v != want:
            wrong.append(f"{name} {v:g} (expected {want:g})")
    if wrong:
        return Check("channel map", False, "the station sends roll, pitch, throttle, yaw on "
                     "channels 1-4: " + ", ".join(wrong))
    return Check("channel map", True, "channels 1-4 roll/pitch/throttle/yaw")


def _battery(dialect: Dialect, get: Callable[[str], float | None],
             battery_v: float | None) -> Check:
    name = "BATT_LOW_VOLT" if dialect is Dialect.COPTER4 else "FS_BATT_VOLTAGE"
    threshold = get(name)
    if battery_v is None or not math.isfinite(battery_v) or battery_v <= 0.0:
        return Check("battery", False, "no battery voltage reported")
    if threshold is None or threshold <= 0.0:
        return Check("battery", True, f"battery {battery_v:.2f} V (no failsafe voltage set)")
    if battery_v < threshold + BATTERY_MARGIN_V:
        return Check("battery", False, f"battery {battery_v:.2f} V is at its failsafe "
                     f"{name} {threshold:g} V")
    return Check("battery", True, f"battery {battery_v:.2f} V above {name} {threshold:g} V")


def read_and_check(get_param: Callable[[str], float], set_param: Callable[[str, float], float],
                   dialect: Dialect, battery_v: float | None, *, fix: bool) -> PreflightReport:
    """Read what `evaluate` needs; with `fix` (the pilot's consent), set the failsafe parameters
    that would make it pass and judge again. `get_param`/`set_param` raise on failure."""
    params: dict[str, float] = {}
    unreadable: dict[str, str] = {}
    for name in required_parameters(dialect):
        try:
            params[name] = float(get_param(name))
        except Exception as exc:  # every failure is reported by name, never a silent default
            unreadable[name] = str(exc) or type(exc).__name__
    report = evaluate(dialect, params, battery_v, unreadable)
    if fix and report.fixes:
        for name, value in report.fixes.items():
            try:
                params[name] = float(set_param(name, value))
            except Exception as exc:
                unreadable[name] = f"set to {value:g} failed: {exc}"
        report = evaluate(dialect, params, battery_v, unreadable)
    return report
