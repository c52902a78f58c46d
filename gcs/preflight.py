"""Pre-flight checks: the vehicle's parameters must make the station's link-loss policy safe.

The station lands a vehicle it cannot hear and then falls silent, so what the autopilot's own
failsafes do on a silent link must be a landing (or a hold, then a landing) without a climb, in
the modes the station flies: `gcs.failsafe_policy` predicts it from the parameters and the GPS
fix. The station also assumes the throttle on channel 3 spanning 1000..2000 µs, sticks on
channels 1–4, and a battery above its failsafe. `evaluate` is pure; `read_and_check` reads the
parameters over the link and, with the pilot's consent, sets what the failsafe needs, reads
every value back and judges again.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from firmware_link.records import Dialect
from gcs import failsafe_policy
from gcs.failsafe_policy import FLOWN_MODES, VehicleState

RC_SPAN_TOLERANCE_US = 50
BATTERY_MARGIN_V = 0.2
FAILSAFE = "failsafe"  # the check whose detail is the failsafe prediction's own line
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
    # what --fix-failsafe changed: (name, before, after as read back)
    fixed: tuple[tuple[str, float, float], ...] = ()
    fix_failed: tuple[str, ...] = ()  # what --fix-failsafe could not set, and why

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
        return "; ".join([f"{c.name}: {c.detail}" if c.name != FAILSAFE else c.detail
                          for c in bad] + [f"--fix-failsafe: {f}" for f in self.fix_failed])

    def fix_line(self) -> str | None:
        """One line saying what `--fix-failsafe` set and what the vehicle will now do (None
        when it set nothing)."""
        if not self.fixed and not self.fix_failed:
            return None
        done = [f"set {', '.join(f'{n} {a:g} -> {b:g}' for n, a, b in self.fixed)} (read back)"]
        done = (done if self.fixed else []) + list(self.fix_failed)
        after = next((c.detail for c in self.checks if c.name == FAILSAFE), "")
        return f"--fix-failsafe: {'; '.join(done)}; {after}"


def required_parameters(dialect: Dialect) -> tuple[str, ...]:
    """What `evaluate` reads for this firmware."""
    names = [*failsafe_policy.required_parameters(dialect), "RC3_MIN", "RC3_MAX", "RC3_TRIM",
             *CHANNEL_MAP]
    names.append("BATT_LOW_VOLT" if dialect is Dialect.COPTER4 else "FS_BATT_VOLTAGE")
    return tuple(names)


def evaluate(dialect: Dialect, params: Mapping[str, float], battery_v: float | None,
             unreadable: Mapping[str, str] | None = None,
             state: VehicleState | None = None) -> PreflightReport:
    """Judge the parameters (`unreadable`: name → why it could not be read; `state`: what the
    vehicle reported, None: nothing, taken at its worst)."""
    missing = dict(unreadable or {})

    def get(name: str) -> float | None:
        return params.get(name) if name not in missing else None

    checks = [_failsafe(dialect, params, missing, state or VehicleState()),
              _throttle_range(get, missing), _channel_map(get, missing),
              _battery(dialect, get, battery_v)]
    return PreflightReport(dialect, tuple(checks))


def _unreadable(name: str, missing: Mapping[str, str]) -> str:
    return f"could not read {name} ({missing.get(name, 'not reported')})"


def _failsafe(dialect: Dialect, params: Mapping[str, float], missing: Mapping[str, str],
              state: VehicleState) -> Check:
    """What the vehicle does on a silent link in every mode the station flies: the first
    unsafe prediction names the parameter and the fix."""
    for name in failsafe_policy.required_parameters(dialect):
        if name in missing or name not in params:
            return Check(FAILSAFE, False, f"{FAILSAFE}: {_unreadable(name, missing)}")
    fix = failsafe_policy.safe_settings(dialect, params, state)
    first = None
    for mode in FLOWN_MODES:
        p = failsafe_policy.predict(dialect, params, state, mode)
        if not p.safe:
            return Check(FAILSAFE, False, p.line(), fix)
        first = first or p
    assert first is not None
    return Check(FAILSAFE, True, first.line())


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
                   dialect: Dialect, battery_v: float | None, *, fix: bool,
                   state: VehicleState | None = None) -> PreflightReport:
    """Read what `evaluate` needs; with `fix` (the pilot's consent), set the failsafe parameters
    that would make it pass, read every parameter back and judge again. `get_param` /
    `set_param` raise on failure (`set_param` returns the value the vehicle stored)."""
    params, unreadable = _read_all(get_param, dialect)
    report = evaluate(dialect, params, battery_v, unreadable, state)
    if not (fix and report.fixes):
        return report
    before = dict(params)
    failed: list[str] = []
    for name, value in report.fixes.items():
        try:
            set_param(name, value)
        except Exception as exc:  # reported by name; the read-back below judges what stuck
            failed.append(f"{name} not set to {value:g} ({exc})")
    params, unreadable = _read_all(get_param, dialect)
    report = evaluate(dialect, params, battery_v, unreadable, state)
    fixed = tuple((n, before[n], params[n]) for n in _changed(before, params))
    return PreflightReport(report.dialect, report.checks, fixed, tuple(failed))


def _changed(before: Mapping[str, float], after: Mapping[str, float]) -> list[str]:
    """The parameters whose value changed, in reading order."""
    return [n for n in after if n in before and after[n] != before[n]]


def _read_all(get_param: Callable[[str], float],
              dialect: Dialect) -> tuple[dict[str, float], dict[str, str]]:
    params: dict[str, float] = {}
    unreadable: dict[str, str] = {}
    for name in required_parameters(dialect):
        try:
            params[name] = float(get_param(name))
        except Exception as exc:  # every failure is reported by name, never a silent default
            unreadable[name] = str(exc) or type(exc).__name__
    return params, unreadable
