"""What the teleop screen shows: one immutable view, built from a live station or a recording.

The app only reads `TeleopView`; where the numbers come from (a `Station` snapshot or a replayed
MCAP file) is the backend's business. `None` means "not known yet" and is shown as a dash.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True)
class LinkView:
    """The link panel."""

    url: str = ""
    dialect: str = ""
    # the firmware as identified ("ArduCopter V4.7.0-dev") and by what ("AUTOPILOT_VERSION");
    # empty: not known (a replay of an older recording), the dialect is shown instead
    firmware: str = ""
    firmware_source: str = ""
    connected: bool = False
    lost: bool = False
    heartbeat_age_s: float | None = None
    msgs_per_s: float | None = None
    rx_lost: int = 0
    rx_bad: int = 0
    signing: bool = False
    recording: str | None = None
    # forwarding: stations sharing the vehicle, and RC overrides of theirs refused
    fwd_stations: int | None = None  # None: not forwarding
    fwd_refused_overrides: int = 0


@dataclass(frozen=True, slots=True)
class VehicleView:
    """Mode, arming, battery, failsafe and attitude."""

    mode: str = ""
    armed: bool = False
    failsafe: bool = False
    battery_v: float | None = None
    battery_pct: int | None = None
    roll_deg: float | None = None
    pitch_deg: float | None = None
    yaw_deg: float | None = None


@dataclass(frozen=True, slots=True)
class AltitudeView:
    """Altitude from each source, the setpoint, and vertical motion (positive up)."""

    sonar_m: float | None = None
    accel_m: float | None = None  # the eq. 6.1 dead-reckoning baseline
    fused_m: float | None = None
    setpoint_m: float | None = None
    climb_mps: float | None = None
    acc_up_mps2: float | None = None
    truth_m: float | None = None
    hold_on: bool = False
    throttle_us: int | None = None


@dataclass(frozen=True, slots=True)
class LoopView:
    """The 25 ms loop measuring itself."""

    period_ms: float | None = None
    jitter_p99_ms: float | None = None
    compute_ms: float | None = None
    overruns: int = 0
    ticks: int = 0


@dataclass(frozen=True, slots=True)
class TeleopView:
    """Everything one redraw needs."""

    t_s: float = 0.0
    link: LinkView = field(default_factory=LinkView)
    vehicle: VehicleView = field(default_factory=VehicleView)
    altitude: AltitudeView = field(default_factory=AltitudeView)
    loop: LoopView = field(default_factory=LoopView)
    # (t_s, fused_m, setpoint_m, sonar_m) and (t_s, acc_up_mps2) for the two graph indicators
    alt_history: tuple[tuple[float, float | None, float | None, float | None], ...] = ()
    acc_history: tuple[tuple[float, float | None], ...] = ()
    # (t_s, text) in order; the app shows those it has not shown yet
    messages: tuple[tuple[float, str], ...] = ()
    replay: str | None = None  # e.g. "▶ 2.0x 12.3/257.0 s" when showing a recording


def fmt(value: float | None, spec: str = ".2f", unit: str = "") -> str:
    """Format a maybe-unknown number for a panel."""
    if value is None:
        return "—"
    return f"{value:{spec}}{unit}"
