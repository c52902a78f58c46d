"""Telemetry bring-up: the stream plan for this vehicle and link, raised in steps and measured.

Thesis §6.1 lowered the sampling period from 100 ms to 25 ms in five steps so the serial link
would not choke; `bring_up` does the same and measures what each step really delivers (see
`streams` for the pure planning).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from firmware_link.errors import LinkUsageError
from firmware_link.firmware import FirmwareInfo
from firmware_link.frames import FrameEndpoint
from firmware_link.records import Dialect, LinkEventKind
from firmware_link.streams import (
    BringUpReport,
    BringUpStep,
    StreamPlan,
    apm25_delivered_hz,
    bring_up_periods_ms,
    fast_rate_limit_hz,
    measured_rate_hz,
    plan_streams,
    step_plan,
    wanted_streams,
)

PLAN_UTILISATION = 0.8  # share of a serial link the telemetry may fill; the rest is headroom


class StreamBringUp:
    """Stream planning and bring-up; mixed into `VehicleLink` (LinkCore supplies the link)."""

    _ep: FrameEndpoint
    _clock: Callable[[], float]
    _signing: bool
    _last_plan: StreamPlan | None
    _rate_probe: dict[str, list[float]] | None
    _byte_probe: dict[str, int]
    _request_rates: Callable[[dict[str, float]], None]
    _hold: Callable[[float], None]
    _event: Callable[[float, LinkEventKind, str], None]
    dialect: Dialect
    firmware: FirmwareInfo
    capacity_bytes_per_s: float | None

    def plan(self, target_rate_hz: float = 40.0) -> StreamPlan:
        """The stream plan for this vehicle and link (no traffic)."""
        return plan_streams(
            self.capacity_bytes_per_s,
            wanted_streams(self.dialect, target_rate_hz),
            wire=self.firmware.wire,
            signed=self._signing,
            grouped=self.dialect is Dialect.APM25,
            max_utilisation=PLAN_UTILISATION,
        )

    def bring_up(
        self,
        target_rate_hz: float = 40.0,
        *,
        step_hold_s: float = 0.4,
        final_window_s: float = 1.5,
        settle_s: float = 0.15,
        tolerance: float = 0.1,
    ) -> BringUpReport:
        """Raise the telemetry rates in five steps to `target_rate_hz` and measure them.

        On a link with a capacity, each step also measures the bytes the link really carries;
        if the fast streams would not fit at the next step (the vehicle sends more than the
        plan knows of), the remaining steps stop at the fastest rate that fits.
        """
        if not 10.0 <= target_rate_hz <= 100.0:
            raise LinkUsageError(f"target rate {target_rate_hz} Hz outside 10..100 Hz")
        plan = self.plan(target_rate_hz)
        self._last_plan = plan
        whole_hz = self.dialect is Dialect.APM25
        capacity = self.capacity_bytes_per_s
        budget = None if capacity is None else capacity * PLAN_UTILISATION
        slowest_fast_hz = max(
            (r.rate_hz for r in plan.rates if r.rate_hz < target_rate_hz), default=0.0
        )
        limit_hz = math.inf
        steps: list[BringUpStep] = []
        measured: dict[str, list[float]] = {}
        periods = bring_up_periods_ms(100.0, 1000.0 / target_rate_hz, 5)
        for k, period in enumerate(periods):
            rates = step_plan(plan, period, whole_hz=whole_hz, limit_hz=limit_hz)
            self._request_rates(rates)
            self._hold(settle_s)
            window = final_window_s if k == len(periods) - 1 else step_hold_s
            self._rate_probe = measured = {}
            self._byte_probe = {}
            bytes_before, t_before = self._ep.tally.rx_bytes, self._clock()
            try:
                self._hold(window)
            finally:
                self._rate_probe = None
            elapsed = max(self._clock() - t_before, 1e-9)
            asked = rates.get("ATTITUDE", 0.0)
            step = BringUpStep(
                period_ms=period,
                requested_hz=asked,
                measured_hz=measured_rate_hz(measured.get("ATTITUDE", []), window),
                rx_bytes_per_s=(self._ep.tally.rx_bytes - bytes_before) / elapsed,
                expected_hz=apm25_delivered_hz(asked) if whole_hz else None,
            )
            steps.append(step)
            # Estimate only once the fast streams clearly outrun the slow ones (their rates
            # tell them apart), and trust the latest, fastest step most.
            last_step = k == len(periods) - 1
            # The fast streams run at what the firmware delivers (3.2.1 rounds to 50/N Hz), so
            # they are told and scaled by the measured rate, not the one asked.
            fast_hz = step.measured_hz if step.measured_hz > 0 else step.requested_hz
            if not last_step and budget is not None and fast_hz >= 1.5 * slowest_fast_hz:
                fast_bytes = sum(
                    self._byte_probe.get(kind, 0)
                    for kind, stamps in measured.items()
                    if len(stamps) / elapsed >= 0.75 * fast_hz
                )
                limit_hz = fast_rate_limit_hz(
                    step.rx_bytes_per_s, fast_bytes / elapsed, fast_hz, budget
                )
        achieved = tuple(
            (r.message, measured_rate_hz(measured.get(r.message, []), final_window_s))
            for r in plan.rates
        )
        last = steps[-1]
        final_hz = last.measured_hz
        reached = abs(final_hz - target_rate_hz) <= tolerance * target_rate_hz
        confirmed = last.delivered(tolerance)
        limited = limit_hz < target_rate_hz
        if capacity is None:
            carried = f"{last.rx_bytes_per_s:.0f} B/s carried (network link)"
        else:
            carried = (
                f"{last.rx_bytes_per_s:.0f} B/s carried of {capacity:.0f} B/s "
                f"({100.0 * last.rx_bytes_per_s / capacity:.0f} %)"
            )
        self._event(
            self._clock(),
            LinkEventKind.STREAMS,
            f"ATTITUDE {final_hz:.1f} Hz of {last.requested_hz:.1f} Hz asked"
            + ("" if last.expected_hz is None else
               f" (the firmware gives {last.expected[0]:.1f}..{last.expected[1]:.1f} Hz)")
            + f"; {carried}"
            + (f"; link budget limits fast streams to {limit_hz:.1f} Hz" if limited else ""),
        )
        return BringUpReport(
            dialect=self.dialect,
            plan=plan,
            steps=tuple(steps),
            achieved_hz=achieved,
            target_rate_hz=target_rate_hz,
            reached=reached,
            confirmed=confirmed,
            limit_hz=limit_hz if limited else None,
        )

