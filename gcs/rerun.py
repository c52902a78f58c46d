"""Re-fly a recorded flight's sensor data through fresh estimator and supervisor
instances, and measure how their outputs differ from what the station computed in the air.

The station records, per tick, which telemetry records and intents it consumed and what it knew
of the vehicle (`/gcs/tick`, a `TickRecord`; the records on their own topics, `/gcs/intent`), and
once its configuration, throttle curve and supervisor policy (`/gcs/setup`). From these the rerun
rebuilds every tick's `TickInputs` exactly as the station's flight core got them and steps a
fresh `FlightCore` on them, so with unchanged parameters every output is bit-identical to the
recording. With changed parameters
(`apply_overrides`) it shows what those gains would have done with the same sensor data.

Not replayed: the vehicle's response. The sensor data are those of the flight as flown, so a
rerun with other gains is an open-loop comparison (the controller's command on the recorded
state), not a new flight. The supervisor (and with it the position controller) is rerun from the
recorded intents and vehicle states; its transitions follow the recorded vehicle, not a new one.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from firmware_link.records import Attitude, Barometer, Imu, MocapPose, Rangefinder
from gcs import params_json, topics
from gcs.config import StationConfig, _build
from gcs.control.altitude_controller import AltControlOutput
from gcs.control.throttle_curve import ThrottleCurve
from gcs.core.flight_core import FlightCore
from gcs.core.inputs import TickInputs, TickRecord
from gcs.errors import UsageError
from gcs.estimation import AltEstimate
from gcs.station.types import StationSetup
from gcs.supervisor import Intent, SupervisorParams
from gcs.toml_file import read_toml
from logs import Recording, RecordingError, from_jsonable

GAIN_ALIASES: dict[str, str] = {
    "alt.": "altitude.gains.",
    "est.": "estimator.",
    "pos.": "position.",
}
"""Short prefixes accepted in `--gains key=value` lists."""


@dataclass(frozen=True, slots=True)
class RecordedFlight:
    """What a rerun reads from a recording: setup, ticks and the station's recorded outputs."""

    config: StationConfig
    curve: ThrottleCurve
    hover_throttle: float
    supervisor: SupervisorParams
    ticks: tuple[TickInputs, ...]
    tick_ns: tuple[int, ...]  # each tick's log time (ns), the key of the outputs below
    estimates: Mapping[int, AltEstimate]  # by log time (ns) of the tick
    alt_outputs: Mapping[int, AltControlOutput]


@dataclass(frozen=True, slots=True)
class RerunOutputs:
    """The fresh instances' outputs, keyed like `RecordedFlight`'s."""

    estimates: Mapping[int, AltEstimate]
    alt_outputs: Mapping[int, AltControlOutput]


@dataclass(frozen=True, slots=True)
class SignalDiff:
    """How one recorded signal and its rerun differ over the ticks both have."""

    signal: str  # topic.field, e.g. "/gcs/estimate.alt_m"
    compared: int
    differing: int  # ticks whose values are not bit-identical
    max_abs: float | None  # None for non-numeric signals; inf when finite meets non-finite
    rms: float | None  # over the ticks where both values are finite

    @property
    def identical(self) -> bool:
        return self.differing == 0


@dataclass(frozen=True, slots=True)
class RerunReport:
    """Per-signal differences between a recording and its rerun."""

    ticks: int
    overrides: tuple[str, ...]  # "key: recorded -> rerun" for every changed parameter
    signals: tuple[SignalDiff, ...]
    only_recorded: int  # ticks with a controller output in the recording but not the rerun
    only_rerun: int

    @property
    def identical(self) -> bool:
        """Every float of every output equal, bit for bit, and the same ticks controlled."""
        return (self.only_recorded == 0 and self.only_rerun == 0
                and all(s.identical for s in self.signals))

    def to_jsonable(self) -> dict[str, Any]:
        """Plain JSON types; non-finite numbers become null."""

        def num(x: float | None) -> float | None:
            return x if x is not None and math.isfinite(x) else None

        return {
            "bit_identical": self.identical,
            "ticks": self.ticks,
            "overrides": list(self.overrides),
            "only_recorded": self.only_recorded,
            "only_rerun": self.only_rerun,
            "signals": [
                {"signal": s.signal, "compared": s.compared, "differing": s.differing,
                 "max_abs": num(s.max_abs), "rms": num(s.rms)}
                for s in self.signals
            ],
        }


# ------------------------------------------------------------------ reading a recording
def _decode(cls: type, message: Mapping[str, Any], where: str) -> Any:
    try:
        return from_jsonable(cls, message)
    except (TypeError, ValueError, KeyError) as exc:
        raise UsageError(f"{where}: not a {cls.__name__} record ({exc})") from None


def load_flight(recording: Recording) -> RecordedFlight:
    """Read the setup, the ticks with their inputs, and the recorded outputs (UsageError when
    the recording lacks them or does not hold enough input records)."""
    name = str(recording.path)
    for needed in (topics.SETUP, topics.TICK, topics.ESTIMATE):
        if needed not in recording.counts:
            raise UsageError(f"{name}: no {needed} topic; the recording cannot be rerun (it needs "
                             f"{topics.SETUP}, {topics.TICK} and {topics.ESTIMATE})")
    wanted = [t for t in (topics.SETUP, topics.TICK, topics.ESTIMATE, topics.ALT_CONTROLLER,
                          topics.IMU, topics.RANGEFINDER, topics.ATTITUDE, topics.BAROMETER,
                          topics.MOCAP_POSE, topics.INTENT)
              if t in recording.counts]
    by_topic: dict[str, list[tuple[int, Mapping[str, Any]]]] = {t: [] for t in wanted}
    try:
        for topic, log_ns, message in recording.messages(wanted):
            by_topic[topic].append((log_ns, message))
    except RecordingError as exc:
        raise UsageError(str(exc)) from None

    setup = _decode(StationSetup, by_topic[topics.SETUP][0][1], f"{name} {topics.SETUP}")
    try:
        config = params_json.loads(StationConfig, setup.config_json)
        curve = params_json.loads(ThrottleCurve, setup.curve_json)
        supervisor = params_json.loads(SupervisorParams, setup.supervisor_json)
    except ValueError as exc:
        raise UsageError(f"{name} {topics.SETUP}: unreadable station setup ({exc})") from None

    def stream(topic: str, cls: type) -> Iterator[Any]:
        for _ns, msg in by_topic.get(topic, []):
            yield _decode(cls, msg, f"{name} {topic}")

    imus, sonars, atts = (stream(topics.IMU, Imu), stream(topics.RANGEFINDER, Rangefinder),
                          stream(topics.ATTITUDE, Attitude))
    baros = stream(topics.BAROMETER, Barometer)
    mocaps, intents = stream(topics.MOCAP_POSE, MocapPose), stream(topics.INTENT, Intent)

    def take(it: Iterator[Any], n: int, topic: str, k: int) -> tuple[Any, ...]:
        got = tuple(r for _, r in zip(range(n), it, strict=False))
        if len(got) < n:
            raise UsageError(f"{name}: tick {k} consumed {n} {topic} records but the recording "
                             f"ran out of them (truncated, or the recorder dropped messages)")
        return got

    ticks: list[TickInputs] = []
    for _ns, msg in by_topic[topics.TICK]:
        t = _decode(TickRecord, msg, f"{name} {topics.TICK}")
        ticks.append(t.inputs(take(imus, t.imu_n, topics.IMU, t.tick),
                              take(sonars, t.rangefinder_n, topics.RANGEFINDER, t.tick),
                              take(atts, t.attitude_n, topics.ATTITUDE, t.tick),
                              take(baros, t.baro_n, topics.BAROMETER, t.tick),
                              take(mocaps, t.mocap_n, topics.MOCAP_POSE, t.tick),
                              take(intents, t.intent_n, topics.INTENT, t.tick)))
    estimates = {ns: _decode(AltEstimate, m, f"{name} {topics.ESTIMATE}")
                 for ns, m in by_topic[topics.ESTIMATE]}
    alts = {ns: _decode(AltControlOutput, m, f"{name} {topics.ALT_CONTROLLER}")
            for ns, m in by_topic.get(topics.ALT_CONTROLLER, [])}
    return RecordedFlight(config, curve, setup.hover_throttle, supervisor, tuple(ticks),
                          tuple(ns for ns, _ in by_topic[topics.TICK]), estimates, alts)


# ------------------------------------------------------------------ the rerun (pure)
def rerun(flight: RecordedFlight, config: StationConfig | None = None) -> RerunOutputs:
    """Step a fresh flight core on the recorded ticks' inputs, as the station stepped its own
    (`config`: the recorded one if None)."""
    cfg = flight.config if config is None else config
    core = FlightCore(cfg, flight.curve, flight.hover_throttle, flight.supervisor)
    estimates: dict[int, AltEstimate] = {}
    alts: dict[int, AltControlOutput] = {}
    for log_ns, inputs in zip(flight.tick_ns, flight.ticks, strict=True):
        out = core.step(inputs)
        estimates[log_ns] = out.estimate
        if out.alt is not None:  # the station records the last output on held ticks too
            alts[log_ns] = out.alt
    return RerunOutputs(estimates, alts)


# ------------------------------------------------------------------ comparing
def _as_float(v: Any) -> float | None:
    if isinstance(v, bool):
        return float(v)
    if isinstance(v, int | float):
        return float(v)
    return None


def _same(a: Any, b: Any) -> bool:
    fa, fb = _as_float(a), _as_float(b)
    if fa is None or fb is None:
        return bool(a == b)
    # recordings keep non-finite floats as null (read back as NaN): any non-finite matches one
    if not math.isfinite(fa) or not math.isfinite(fb):
        return not math.isfinite(fa) and not math.isfinite(fb)
    return fa.hex() == fb.hex()


def _diff_signal(signal: str, pairs: list[tuple[Any, Any]]) -> SignalDiff:
    differing = sum(not _same(a, b) for a, b in pairs)
    numeric = pairs and all(_as_float(a) is not None and not isinstance(a, enum.Enum)
                            for a, _ in pairs)
    if not numeric:
        return SignalDiff(signal, len(pairs), differing, None, None)
    max_abs, sq, n = 0.0, 0.0, 0
    for a, b in pairs:
        fa, fb = _as_float(a), _as_float(b)
        assert fa is not None and fb is not None
        if math.isfinite(fa) and math.isfinite(fb):
            d = abs(fa - fb)
            max_abs, sq, n = max(max_abs, d), sq + d * d, n + 1
        elif math.isfinite(fa) != math.isfinite(fb):
            max_abs = math.inf
    return SignalDiff(signal, len(pairs), differing, max_abs, math.sqrt(sq / n) if n else 0.0)


def _diff_topic(topic: str, cls: type, recorded: Mapping[int, Any],
                fresh: Mapping[int, Any]) -> list[SignalDiff]:
    common = [ns for ns in recorded if ns in fresh]
    return [
        _diff_signal(f"{topic}.{f.name}",
                     [(getattr(recorded[ns], f.name), getattr(fresh[ns], f.name))
                      for ns in common])
        for f in dataclasses.fields(cls)
    ]


def compare(flight: RecordedFlight, outputs: RerunOutputs,
            overrides: tuple[str, ...] = ()) -> RerunReport:
    """Per-signal differences of the estimate and the altitude controller's output."""
    signals = (_diff_topic(topics.ESTIMATE, AltEstimate, flight.estimates, outputs.estimates)
               + _diff_topic(topics.ALT_CONTROLLER, AltControlOutput, flight.alt_outputs,
                             outputs.alt_outputs))
    missing_est = sum(ns not in outputs.estimates for ns in flight.estimates)
    only_recorded = sum(ns not in outputs.alt_outputs for ns in flight.alt_outputs) + missing_est
    only_rerun = sum(ns not in flight.alt_outputs for ns in outputs.alt_outputs)
    return RerunReport(len(flight.ticks), overrides, tuple(signals), only_recorded, only_rerun)


# ------------------------------------------------------------------ parameter overrides
def parse_gains(spec: str) -> dict[str, Any]:
    """`--gains` text → a nested override table. Either a TOML file laid out as the station
    config, or `key=value[,key=value...]` with dotted StationConfig paths (`altitude.gains.kp`)
    or their short forms (`alt.kp`, `est.sonar_sigma_m`, `pos.…`); values are TOML values."""
    path = Path(spec)
    if spec.endswith(".toml") or path.is_file():
        return read_toml(path, label=f"--gains {spec}")
    table: dict[str, Any] = {}
    for item in filter(None, (s.strip() for s in spec.split(","))):
        key, eq, text = item.partition("=")
        key = key.strip()
        if not eq or not key or not text.strip():
            raise UsageError(f"--gains {item!r}: expected key=value, e.g. alt.kp=1.2")
        for short, full in GAIN_ALIASES.items():
            if key.startswith(short):
                key = full + key[len(short):]
        try:
            value = tomllib.loads(f"v = {text.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = text.strip()  # a bare word: an enum value such as complementary
        node = table
        *parents, leaf = key.split(".")
        for part in parents:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise UsageError(f"--gains {key}: {part} is both a value and a table")
            node = child
        node[leaf] = value
    if not table:
        raise UsageError(f"--gains {spec!r}: nothing to change; expected key=value or a .toml file")
    return table


def apply_overrides(config: StationConfig, table: Mapping[str, Any]) -> StationConfig:
    """`config` with the override table applied (unknown keys, wrong types: UsageError)."""
    built: StationConfig = _build(config, dict(table), "--gains ")
    return built


def changed_parameters(before: Any, after: Any, prefix: str = "") -> tuple[str, ...]:
    """"path: old -> new" for every field that differs between two parameter dataclasses."""
    out: list[str] = []
    for f in dataclasses.fields(before):
        a, b = getattr(before, f.name), getattr(after, f.name)
        if dataclasses.is_dataclass(a) and not isinstance(a, type):
            out.extend(changed_parameters(a, b, f"{prefix}{f.name}."))
        elif a != b:
            out.append(f"{prefix}{f.name}: {_show(a)} -> {_show(b)}")
    return tuple(out)


def _show(value: Any) -> str:
    return str(value.value if isinstance(value, enum.Enum) else value)


def format_report(report: RerunReport, name: str) -> list[str]:
    """Human-readable lines: a verdict, the changed parameters, then the differing signals."""
    lines = [f"rerun of {name}: {report.ticks} ticks"]
    lines += [f"  changed {c}" for c in report.overrides] or ["  parameters as recorded"]
    if report.identical:
        lines.append("bit-identical: every estimate and altitude-controller output equals the "
                     "recording")
        return lines
    differing = [s for s in report.signals if not s.identical]
    lines.append(f"DIFFERS: {len(differing)} of {len(report.signals)} signals"
                 + (f", {report.only_recorded} outputs only in the recording"
                    if report.only_recorded else "")
                 + (f", {report.only_rerun} only in the rerun" if report.only_rerun else ""))
    lines.append(f"  {'signal':<38} {'ticks differ':>14} {'max |diff|':>12} {'rms diff':>12}")
    for s in differing:
        mx = "-" if s.max_abs is None else f"{s.max_abs:.6g}"
        rms = "-" if s.rms is None else f"{s.rms:.6g}"
        lines.append(f"  {s.signal:<38} {f'{s.differing}/{s.compared}':>14} {mx:>12} {rms:>12}")
    return lines
