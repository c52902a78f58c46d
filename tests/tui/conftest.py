"""Shared pieces for the TUI tests: a fixed view, for screens that must render identically."""

from __future__ import annotations

from gcs.pilot import intents
from gcs.pilot.view import AltitudeView, LinkView, LoopView, TeleopView, VehicleView


def fixed_view() -> TeleopView:
    """A mid-flight view with every panel filled, deterministic to the digit."""
    alt = tuple(
        (10.0 + 0.1 * i, 0.6 + 0.004 * i, 1.0, 0.61 + 0.004 * i if i % 7 else None)
        for i in range(100)
    )
    acc = tuple((10.0 + 0.1 * i, 0.3 - 0.006 * i) for i in range(100))
    return TeleopView(
        t_s=20.0,
        link=LinkView(url="tcp:127.0.0.1:5760", dialect="apm25", connected=True,
                      heartbeat_age_s=0.4, msgs_per_s=318.0, rx_lost=2, rx_bad=1,
                      recording="flights/2026-11-22T10-31-05Z_vehicle1.mcap"),
        vehicle=VehicleView(mode="STABILIZE", armed=True, battery_v=11.92, battery_pct=87,
                            roll_deg=1.2, pitch_deg=-0.8, yaw_deg=93.5),
        altitude=AltitudeView(sonar_m=0.998, accel_m=1.041, fused_m=0.996, setpoint_m=1.0,
                              climb_mps=0.02, acc_up_mps2=-0.11, truth_m=1.003, hold_on=True,
                              throttle_us=1492),
        loop=LoopView(period_ms=25.0, jitter_p99_ms=0.41, compute_ms=0.9, overruns=0,
                      ticks=800),
        alt_history=alt,
        acc_history=acc,
        messages=((0.0, "recording to flights/2026-11-22T10-31-05Z_vehicle1.mcap"),
                  (3.2, "arm requested"), (9.8, "altitude hold on, setpoint 1.00 m")),
    )


class FixedBackend:
    """Always shows the same view and keeps every intent it is sent."""

    live = True

    def __init__(self) -> None:
        self.sent: list[intents.Intent] = []
        self.closed = False

    def view(self) -> TeleopView:
        return fixed_view()

    def send(self, intent: intents.Intent) -> None:
        self.sent.append(intent)

    def close(self) -> None:
        self.closed = True
