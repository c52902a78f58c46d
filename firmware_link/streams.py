"""Telemetry stream planning: which message at which rate fits the link, and the bring-up steps.

The byte budget is payload + frame overhead (MAVLink 1: 8 bytes; MAVLink 2: 12, +13 signed)
times rate, summed, against the medium's capacity (115200 baud 8N1 ≈ 11,520 B/s). Network links
have no capacity limit here (None). `plan_streams` is pure and tested without a link.

ArduCopter 3.2.1 can only set rates per stream group (`REQUEST_DATA_STREAM`, integer Hz), so
messages of one group share its rate; 4.x sets each message (`SET_MESSAGE_INTERVAL`).

Bring-up follows thesis §6.1: the sampling period was lowered from 100 ms to 25 ms in five steps
of about 100 ms each so the serial link would not choke. Here the steps are equal in period
(100, 85, 70, 55, 40, 25 ms → 10, 11.8, 14.3, 18.2, 25, 40 Hz) and each holds long enough to
measure the ATTITUDE rate reached (100 ms is too short to count a 10 Hz stream).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

from firmware_link.errors import LinkError
from firmware_link.protocol import WireVersion, frame_overhead_bytes, payload_bytes
from firmware_link.records import Dialect


class DataStream(enum.IntEnum):
    """MAV_DATA_STREAM groups of REQUEST_DATA_STREAM."""

    RAW_SENSORS = 1
    EXTENDED_STATUS = 2
    RC_CHANNELS = 3
    POSITION = 6
    EXTRA1 = 10
    EXTRA2 = 11
    EXTRA3 = 12


@dataclass(frozen=True, slots=True)
class StreamWanted:
    """A message the station wants, at `rate_hz`, and the least it can live with."""

    message: str
    rate_hz: float
    min_rate_hz: float
    group: DataStream


@dataclass(frozen=True, slots=True)
class StreamRate:
    """One planned message: its rate and what it costs on the wire."""

    message: str
    group: DataStream
    rate_hz: float
    frame_bytes: int
    bytes_per_s: float


@dataclass(frozen=True, slots=True)
class StreamPlan:
    """Rates chosen to fit the link, and the budget they use."""

    capacity_bytes_per_s: float | None
    wire: WireVersion
    signed: bool
    rates: tuple[StreamRate, ...]

    @property
    def total_bytes_per_s(self) -> float:
        """Bytes per second the planned streams put on the link."""
        return sum(r.bytes_per_s for r in self.rates)

    @property
    def utilisation_pct(self) -> float | None:
        """Share of the link's capacity used, percent; None on an unlimited link."""
        if self.capacity_bytes_per_s is None:
            return None
        return 100.0 * self.total_bytes_per_s / self.capacity_bytes_per_s

    def rate_of(self, message: str) -> float:
        """Planned rate of `message` in Hz (0 when not planned)."""
        return next((r.rate_hz for r in self.rates if r.message == message), 0.0)

    def group_rates(self) -> dict[DataStream, float]:
        """Rate of each stream group (the fastest of its messages)."""
        out: dict[DataStream, float] = {}
        for r in self.rates:
            out[r.group] = max(out.get(r.group, 0.0), r.rate_hz)
        return out

    def budget_lines(self) -> list[str]:
        """The budget as a table a person reads: one line per message, then the total."""
        lines = [f"{'message':<18}{'rate Hz':>9}{'frame B':>9}{'B/s':>9}"]
        for r in self.rates:
            lines.append(
                f"{r.message:<18}{r.rate_hz:>9.1f}{r.frame_bytes:>9d}{r.bytes_per_s:>9.0f}"
            )
        cap = self.capacity_bytes_per_s
        if cap is None:
            lines.append(
                f"total {self.total_bytes_per_s:.0f} B/s (network link, no capacity limit)"
            )
        else:
            lines.append(
                f"total {self.total_bytes_per_s:.0f} B/s of {cap:.0f} B/s "
                f"({self.utilisation_pct:.1f} % of the link)"
            )
        return lines


def _frame_bytes(message: str, wire: WireVersion, signed: bool) -> int:
    return payload_bytes(message, wire) + frame_overhead_bytes(wire, signed)


def plan_streams(
    capacity_bytes_per_s: float | None,
    wanted: Sequence[StreamWanted],
    *,
    wire: WireVersion = WireVersion.V2,
    signed: bool = False,
    grouped: bool = False,
    max_utilisation: float = 0.8,
) -> StreamPlan:
    """Choose rates that fit `max_utilisation` of the capacity, earlier entries first.

    Every entry first gets its minimum rate; then, in the order given (priority), each is raised
    toward its wanted rate as far as the remaining budget allows. With `grouped`, entries of one
    stream group move together (REQUEST_DATA_STREAM). Raises LinkError when even the minimum
    rates do not fit. The headroom left is for STATUSTEXT, PARAM_VALUE and the companion board.
    """
    if not 0.0 < max_utilisation <= 1.0:
        raise ValueError(f"max_utilisation {max_utilisation} outside (0, 1]")
    blocks: dict[object, list[StreamWanted]] = {}
    for w in wanted:
        if w.rate_hz <= 0 or w.min_rate_hz < 0 or w.min_rate_hz > w.rate_hz:
            raise ValueError(f"{w.message}: need 0 <= min_rate_hz <= rate_hz and rate_hz > 0")
        blocks.setdefault(w.group if grouped else w.message, []).append(w)
    cost = {
        key: sum(_frame_bytes(w.message, wire, signed) for w in members)
        for key, members in blocks.items()
    }
    rate = {key: max(w.min_rate_hz for w in members) for key, members in blocks.items()}
    budget = None if capacity_bytes_per_s is None else capacity_bytes_per_s * max_utilisation
    if budget is not None:
        used = sum(cost[k] * rate[k] for k in blocks)
        if used > budget:
            raise LinkError(
                f"telemetry minimum needs {used:.0f} B/s but the link carries "
                f"{budget:.0f} B/s ({max_utilisation:.0%} of {capacity_bytes_per_s:.0f})"
            )
        for key, members in blocks.items():
            want = max(w.rate_hz for w in members)
            spare = budget - sum(cost[k] * rate[k] for k in blocks)
            rate[key] = min(want, rate[key] + spare / cost[key])
            if grouped:
                # REQUEST_DATA_STREAM takes whole Hz; round down so the plan still fits.
                rate[key] = max(float(int(rate[key])), max(w.min_rate_hz for w in members))
    else:
        rate = {key: max(w.rate_hz for w in members) for key, members in blocks.items()}
    rates = tuple(
        StreamRate(
            message=w.message,
            group=w.group,
            rate_hz=rate[w.group if grouped else w.message],
            frame_bytes=_frame_bytes(w.message, wire, signed),
            bytes_per_s=_frame_bytes(w.message, wire, signed)
            * rate[w.group if grouped else w.message],
        )
        for w in wanted
    )
    return StreamPlan(capacity_bytes_per_s, wire, signed, rates)


def wanted_streams(dialect: Dialect, target_rate_hz: float = 40.0) -> tuple[StreamWanted, ...]:
    """The station's telemetry wish list for a firmware, most important first."""
    fast = target_rate_hz
    ds = DataStream
    if dialect is Dialect.APM25:
        return (
            # no ground truth here: a real APM 2.5 sends none, and the SITL's SIM_STATE rides in
            # EXTRA1 capped at 10 Hz on serial, outside what the station plans for
            StreamWanted("ATTITUDE", fast, 10.0, ds.EXTRA1),
            StreamWanted("RAW_IMU", fast, 10.0, ds.RAW_SENSORS),
            StreamWanted("SCALED_PRESSURE", fast, 10.0, ds.RAW_SENSORS),
            StreamWanted("RANGEFINDER", fast, 10.0, ds.EXTRA3),
            StreamWanted("VFR_HUD", 10.0, 2.0, ds.EXTRA2),
            StreamWanted("SYS_STATUS", 2.0, 1.0, ds.EXTENDED_STATUS),
            StreamWanted("RC_CHANNELS_RAW", 5.0, 1.0, ds.RC_CHANNELS),
            StreamWanted("SERVO_OUTPUT_RAW", 5.0, 1.0, ds.RC_CHANNELS),
        )
    return (
        StreamWanted("ATTITUDE", fast, 10.0, ds.EXTRA1),
        StreamWanted("RAW_IMU", fast, 10.0, ds.RAW_SENSORS),
        StreamWanted("DISTANCE_SENSOR", fast, 10.0, ds.EXTRA3),
        StreamWanted("VFR_HUD", 10.0, 2.0, ds.EXTRA2),
        StreamWanted("SYS_STATUS", 2.0, 1.0, ds.EXTENDED_STATUS),
        StreamWanted("SCALED_PRESSURE", 10.0, 1.0, ds.RAW_SENSORS),
        StreamWanted("RC_CHANNELS", 5.0, 1.0, ds.RC_CHANNELS),
        StreamWanted("SERVO_OUTPUT_RAW", 5.0, 1.0, ds.RC_CHANNELS),
        StreamWanted("SIM_STATE", 10.0, 1.0, ds.EXTRA1),
        # the pre-flight judges the failsafe by the GPS fix (RTL navigates with one); 3.2.1
        # sends it with SYS_STATUS's group, 4.x only when asked
        StreamWanted("GPS_RAW_INT", 2.0, 0.5, ds.EXTENDED_STATUS),
    )


APM25_LOOP_HZ = 50.0  # ArduCopter 3.2.1 runs its stream loop (gcs_data_stream_send) at 50 Hz


def apm25_delivered_hz(requested_hz: float) -> tuple[float, float]:
    """The slowest and fastest rate ArduCopter 3.2.1 delivers for a REQUEST_DATA_STREAM rate.

    Its stream loop triggers a group every int(50 / rate) + stream_slowdown ticks
    (`stream_trigger`: ticks = 50 / rate - 1 + stream_slowdown, truncated to a uint8), and
    stream_slowdown is 0 or 1 by how full the port is. So a rate r arrives at 50 / N Hz:
    25 Hz asked gives 25 or 16.7 Hz (16.4 measured on the real firmware), 40 Hz gives 50 or
    25 Hz, never 40.
    """
    rate = min(APM25_LOOP_HZ, float(int(requested_hz)))
    if rate <= 0:
        return 0.0, 0.0
    ticks = int(APM25_LOOP_HZ / rate)
    return APM25_LOOP_HZ / (ticks + 1), APM25_LOOP_HZ / ticks


def bring_up_periods_ms(
    start_ms: float = 100.0, end_ms: float = 25.0, steps: int = 5
) -> tuple[float, ...]:
    """Sampling periods from `start_ms` down to `end_ms` in `steps` equal steps (thesis §6.1)."""
    if steps < 1 or end_ms <= 0 or start_ms < end_ms:
        raise ValueError("need steps >= 1 and start_ms >= end_ms > 0")
    return tuple(start_ms - (start_ms - end_ms) * k / steps for k in range(steps + 1))


def step_plan(
    plan: StreamPlan, period_ms: float, *, whole_hz: bool, limit_hz: float = math.inf
) -> dict[str, float]:
    """Per-message rates for one bring-up step: the plan, capped at 1/period and `limit_hz`.

    With `whole_hz` (REQUEST_DATA_STREAM) the step rate is rounded to whole Hz and the budget
    limit rounded down, so a limited rate still fits.
    """
    step_hz = 1000.0 / period_ms
    if whole_hz:
        step_hz = float(round(step_hz))
        limit_hz = float(math.floor(limit_hz)) if math.isfinite(limit_hz) else limit_hz
    cap_hz = max(1.0, min(step_hz, limit_hz))
    return {r.message: min(r.rate_hz, cap_hz) for r in plan.rates}


def fast_rate_limit_hz(
    rx_bytes_per_s: float, fast_bytes_per_s: float, step_rate_hz: float, budget_bytes_per_s: float
) -> float:
    """Fastest common rate for the fast streams that keeps the link inside its budget.

    Measured during one bring-up step: everything the link carried (`rx_bytes_per_s`) and the
    part that runs at the step's rate (`fast_bytes_per_s`, including any traffic the plan did
    not know of that scales with it, e.g. an extra message in a stream group). The rest stays
    as it is when the fast streams speed up: budget = rest + fast bytes per cycle × rate.
    """
    if fast_bytes_per_s <= 0 or step_rate_hz <= 0:
        return math.inf
    per_cycle = fast_bytes_per_s / step_rate_hz
    rest = max(0.0, rx_bytes_per_s - fast_bytes_per_s)
    return max(0.0, (budget_bytes_per_s - rest) / per_cycle)


@dataclass(frozen=True, slots=True)
class BringUpStep:
    """One bring-up step: the ATTITUDE rate asked for and the rate measured."""

    period_ms: float
    requested_hz: float
    measured_hz: float
    rx_bytes_per_s: float = 0.0  # everything the link carried during the window
    # what the firmware delivers for the rate asked: (slowest, fastest); 3.2.1 rounds to 50/N Hz
    expected_hz: tuple[float, float] | None = None

    @property
    def expected(self) -> tuple[float, float]:
        """(slowest, fastest) rate the firmware should deliver for `requested_hz`."""
        return self.expected_hz or (self.requested_hz, self.requested_hz)

    def delivered(self, tolerance: float = 0.1) -> bool:
        """The measured rate is one the firmware delivers for the rate asked."""
        low, high = self.expected
        return low * (1.0 - tolerance) <= self.measured_hz <= high * (1.0 + tolerance)


@dataclass(frozen=True, slots=True)
class BringUpReport:
    """Outcome of link bring-up: the plan, each step, and the rates reached at the end."""

    dialect: Dialect
    plan: StreamPlan
    steps: tuple[BringUpStep, ...]
    achieved_hz: tuple[tuple[str, float], ...]
    target_rate_hz: float
    reached: bool  # ATTITUDE measured within the tolerance of the target rate
    confirmed: bool = True  # ATTITUDE measured within the tolerance of the rate last asked
    limit_hz: float | None = None  # fast-stream rate the measured link budget allowed

    def achieved(self, message: str) -> float:
        """Rate measured for `message` over the final window (0 when none arrived)."""
        return dict(self.achieved_hz).get(message, 0.0)

    def summary_lines(self) -> list[str]:
        """Human-readable bring-up report: steps, budget, achieved rates."""
        lines = [f"link bring-up ({self.dialect.value}):"]
        for s in self.steps:
            low, high = s.expected
            exact = low == high == s.requested_hz
            gives = "" if exact else f" (gives {low:.1f}..{high:.1f})"
            lines.append(
                f"  step {s.period_ms:5.1f} ms: ATTITUDE asked {s.requested_hz:5.1f} Hz{gives}, "
                f"got {s.measured_hz:5.1f} Hz; link carried {s.rx_bytes_per_s:6.0f} B/s"
            )
        lines.extend("  " + line for line in self.plan.budget_lines())
        for name, hz in self.achieved_hz:
            lines.append(
                f"  achieved {name:<18}{hz:6.1f} Hz (planned {self.plan.rate_of(name):.1f})"
            )
        if self.limit_hz is not None:
            lines.append(f"  link budget measured: fast streams limited to {self.limit_hz:.1f} Hz")
        if self.reached:
            lines.append("  target reached")
        elif self.dialect is Dialect.APM25 and self.confirmed:
            low, high = self.steps[-1].expected
            lines.append(
                f"  target NOT reached: ArduCopter 3.2.1 sends {self.target_rate_hz:.0f} Hz as "
                f"{low:.1f} or {high:.1f} Hz (50/N); rate asked confirmed"
            )
        else:
            asked = "confirmed" if self.confirmed else "NOT confirmed"
            lines.append(f"  target NOT reached; rate asked {asked}")
        return lines


def measured_rate_hz(stamps_s: Sequence[float], window_s: float) -> float:
    """Arrival rate from receive times inside one window: intervals over their span."""
    if len(stamps_s) >= 3:
        span = stamps_s[-1] - stamps_s[0]
        if span > 0:
            return (len(stamps_s) - 1) / span
    return len(stamps_s) / window_s if window_s > 0 else 0.0
