"""What a scripted flight is made of: its phases and the supervisor states each may see, the
plan, one sample per tick, and the score card (`gcs.flight` flies them)."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from gcs.estimation import EstimatorCounts
from gcs.launch import ARM_TIMEOUT_S, REST_S
from gcs.scoring import StepMetrics
from gcs.supervisor import SupervisorState


class Phase(enum.Enum):
    """Where the flight is."""

    GROUND = "ground"
    ARMED = "armed"  # on the floor, armed, before take-off
    TAKEOFF = "takeoff"
    SETTLE = "settle"
    HOLD = "hold"
    STEP = "step"
    LAND = "land"
    DONE = "done"


_S = SupervisorState
PHASE_STATES: dict[Phase, frozenset[SupervisorState]] = {
    # the take-off request is applied at the next tick: until then the supervisor says MANUAL
    Phase.ARMED: frozenset({_S.MANUAL, _S.SPOOL_UP, _S.TAKEOFF, _S.HOLD}),
    Phase.TAKEOFF: frozenset({_S.SPOOL_UP, _S.TAKEOFF, _S.HOLD}),
    Phase.SETTLE: frozenset({_S.HOLD}),
    Phase.HOLD: frozenset({_S.HOLD}),
    Phase.STEP: frozenset({_S.HOLD}),
    Phase.LAND: frozenset({_S.HOLD, _S.VEHICLE, _S.DISARMED}),
}
"""The supervisor states a flight phase may see; any other ends the flight as failed."""


@dataclass(frozen=True, slots=True)
class FlightSample:
    """One tick of the flight: times in the station clock's seconds, altitudes up."""

    t_s: float
    phase: Phase
    setpoint_m: float | None
    target_m: float | None
    est_alt_m: float | None
    truth_alt_m: float | None
    throttle_us: int


@dataclass(frozen=True, slots=True)
class FlightPlan:
    """What to fly."""

    alt_m: float = 1.0
    hold_s: float = 30.0
    settle_s: float = 4.0
    step_m: float = 0.0  # 0: no step
    step_observe_s: float = 8.0
    step_band_m: float = 0.05
    step_smooth_s: float = 0.5  # moving average applied before the band test (see StepMetrics)
    climb_mps: float = 0.5
    descent_mps: float = 0.3
    handover_alt_m: float = 0.15
    arm_timeout_s: float = ARM_TIMEOUT_S
    # disarmed on the floor before arming, so the estimator learns the accelerometer's bias
    # from a vehicle known to stand still (over carpet it has to coast on it for up to 1.2 s)
    rest_s: float = REST_S
    takeoff_delay_s: float = 0.0  # armed on the floor this long before taking off

    def __post_init__(self) -> None:
        if not 0.2 <= self.alt_m <= 3.5:
            raise ValueError(f"altitude {self.alt_m} m outside 0.2..3.5 m (the sonar's range)")
        if self.hold_s <= 0.0:
            raise ValueError(f"hold time must be > 0 s, got {self.hold_s}")
        if not 0.0 < self.arm_timeout_s <= 600.0:
            raise ValueError(f"arm timeout {self.arm_timeout_s} s outside 0..600 s")
        if self.takeoff_delay_s < 0.0:
            raise ValueError(f"take-off delay must be >= 0 s, got {self.takeoff_delay_s}")
        if self.step_m and self.step_observe_s <= self.step_smooth_s:
            raise ValueError(f"the step must be watched longer than {self.step_smooth_s} s, got "
                             f"{self.step_observe_s}")
        if self.step_m and not self.step_band_m > 0.0:
            raise ValueError(f"the step's band must be > 0 m, got {self.step_band_m}")
        if not 0.2 <= self.alt_m + self.step_m <= 3.5:
            raise ValueError(f"step to {self.alt_m + self.step_m} m leaves 0.2..3.5 m")


@dataclass(frozen=True, slots=True)
class FlightSummary:
    """The flight's score card."""

    rms_error_m: float  # hold: against the setpoint; rms² = mean² + std²
    max_error_m: float
    error_source: str  # "truth", "estimate" (no truth at all) or "none"
    mean_error_m: float  # the hold's bias (altitude minus setpoint)
    std_error_m: float  # its spread about that bias
    truth_coverage: float  # share of the hold with a current truth report (0..1)
    truth_rate_hz: float  # distinct truth reports per second in the hold
    step: StepMetrics | None
    jitter_p50_ms: float
    jitter_p99_ms: float
    compute_p99_ms: float
    overruns: int
    ticks: int
    rx_messages: int
    lost_messages: int
    corrupted: int
    hover_throttle: float
    samples: tuple[FlightSample, ...] = field(repr=False)
    estimator: EstimatorCounts | None = None
