"""The supervisor's tuning and the per-firmware facts its policy depends on.

Link-loss policy (the same decision in both dialects; what differs is how the firmware then
behaves, which the pre-flight checks make safe):

- Proof of life is any frame from the vehicle. A gap over `degraded_after_s` holds a safe
  command (hover throttle, level; minimum on the floor) and freezes the altitude controller;
  the controller resumes when frames come back.
- A gap over `lost_after_s` lands the vehicle: SET_MODE LAND every `mode_resend_s` for
  `land_request_s` while the uplink may still work, with that safe throttle in the overrides.
- Still nothing heard after that: LAND keeps being asked, with heartbeats, until a heartbeat
  shows the vehicle disarmed; nothing goes quiet on a vehicle that may still be armed. If the
  uplink works the vehicle is in LAND (it accepts LAND in every state it can fly in); if it does
  not, what the station sends never arrives and the autopilot's own GCS failsafe lands it
  (3.2.1 5 s after the last heartbeat or override; 4.x after FS_GCS_TIMEOUT, which the pre-flight
  checks require to act, and to land). Once a LAND from the height last seen has had time to
  touch down (`land_speed_mps`, `landed_settle_s`) the throttle goes to minimum: ArduCopter 3.2.1
  disarms after LAND only with the throttle at minimum, and a station that then went quiet left
  it landed and armed to its GCS failsafe, whose RTL took it back up to 14 m (measured).
  By then either firmware is in LAND (ours, or its failsafe's, which ignores the stick), so the
  minimum cannot drop a vehicle that still flies on the station's throttle.
- When the link returns nothing resumes: a vehicle in LAND is left landing, a disarmed one stays
  disarmed, one still in STABILIZE keeps being asked to LAND. The pilot re-engages.
- Motion capture is not used to keep flying through a loss: it tells where the vehicle is, not
  whether it is armed, in which mode, or whether the station's commands arrive.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from firmware_link.records import Dialect
from gcs.supervisor.envelope import BlindFlight
from gcs.supervisor.types import LinkHealth


@dataclass(frozen=True, slots=True)
class SupervisorParams:
    """Timings in seconds of the station clock, PWM in µs."""

    # several frames missing whatever the stream rate (3.2.1 sends ~25 Hz, and a dozen message
    # types): past this the estimate only extrapolates, and a PID acting on it runs away
    degraded_after_s: float = 0.15
    # ArduCopter 3.2.1 goes quiet for up to ~1 s while it arms (it recalibrates the barometer
    # in its main loop: the fixture tlog has gaps of 0.85 s and 1.01 s), so 1.5 s, not less
    lost_after_s: float = 1.5
    land_request_s: float = 3.0  # LAND asked with the hover this long, then its descent counts
    mode_resend_s: float = 0.5
    disarm_resend_s: float = 0.2  # kill: ≥ 5 Hz
    arm_resend_s: float = 1.0
    # A pilot's arm is asked again each arm_resend_s for this long, then expires and says so: on
    # the real 4.7 (pre-arm refused ~24 s after boot) an arm kept asked for 30 s armed the vehicle
    # by itself 20 s after the key. A launch that means to wait asks for longer (Intent.wait_s).
    arm_timeout_s: float = 5.0
    # A take-off asked while arming waits this long for the arm, then expires and says so: on
    # the real 4.7 a take-off key pressed while pre-arm refused stayed queued and the vehicle
    # took off by itself when it armed 20 s later.
    takeoff_wait_s: float = 3.0
    # After arming, motors held at minimum: ArduCopter 4.x keeps them there ~2 s, then spools up
    # over MOT_SPOOL_TIME (0.5 s); 3.2.1 spins at once.
    spool_s: float = 0.5
    force_disarm: bool = False  # 4.x takes 21196 to disarm in the air; 3.2.1 has no force
    # 3.2.1 refuses to disarm outside a manual mode until landed: a kill switches to STABILIZE
    stabilize_to_disarm: bool = True
    ramp_below_hover_us: int = 150  # the take-off ramp starts this far below the hover stick
    ramp_rate_us_per_s: float = 100.0
    # ...and from this far below it on, where the vehicle may leave the floor, climbs slower:
    # what the ramp adds while lift-off is being recognised is what the vehicle climbs on
    ramp_slow_band_us: int = 50
    ramp_slow_rate_us_per_s: float = 40.0
    # ...and gives up this far above it. Not more: a ramp's last override is what the vehicle
    # flies blind when the uplink dies (until its failsafe acts, 2-5 s), and 250 us over hover
    # is a climb of ~5 m/s after 1 s (ECOSYSTEM: +100 us, +2.2 m/s after 1 s)
    ramp_above_hover_us: int = 100
    takeoff_give_up_s: float = 3.0  # at the top of the ramp without leaving the floor
    liftoff_rise_m: float = 0.04  # above the rest height ...
    liftoff_vel_mps: float = 0.08  # ... and climbing: airborne
    liftoff_lag_s: float = 0.2  # the ramp's last stretch, spent before lift-off was felt
    # No hold below the rangefinder's minimum range plus this margin: a take-off target, or a
    # hold asked low, goes at least this far above the sonar's blind band, where the estimate
    # has the sonar again (FlightCore: sonar_min_m + sonar_offset_m + this)
    blind_margin_m: float = 0.1
    pickup_band_us: int = 25  # the pilot's throttle takes over within this of the held one
    quit_timeout_s: float = 10.0  # a quitting station waits this long for LAND to show
    # Both firmwares' LAND sinks at LAND_SPEED 50 cm/s below 10 m; their land detectors then take
    # about a second (3.2.1) to decide, with a margin: a LAND asked on a lost link is taken to
    # have touched down after land_request_s + height / land_speed_mps + landed_settle_s.
    land_speed_mps: float = 0.5
    landed_settle_s: float = 3.0
    # A vehicle in LAND that has not disarmed this long after LAND showed is reported (again
    # each period); throttle minimum and heartbeats go on until it is seen disarmed.
    disarm_report_s: float = 30.0
    # The hold asking for nearly all the climb it may (AltitudeControllerParams) this long
    # while the estimate does not rise: a vehicle given +3 m/s² for a second climbs 3 m/s, so
    # either the estimate is not the vehicle's (it was pinned to the floor of a carpet while the
    # take-off drove the vehicle into the ceiling) or the thrust is gone. Either way the PC
    # cannot fly it: the vehicle's own LAND takes over, as ArduCopter's thrust-loss check does.
    blocked_climb_s: float = 2.0
    # The firmware disarms by itself once landed with the throttle at minimum this long:
    # 3.2.1's AUTO_DISARMING_DELAY is a compile-time 15 s; 4.x's DISARM_DELAY defaults to 10 s.
    # Whatever arms a vehicle on the floor must take off (or disarm it) well before.
    auto_disarm_s: float = 15.0
    # A hold's command flown blind (envelope.py): for this long (3.2.1's radio failsafe at 2 s;
    # 4.x's FS_GCS_TIMEOUT, under RC_OVERRIDE_TIME's default 3 s), then the firmware's LAND
    # brakes at least this hard (its z controller allows 2.5 m/s²), and the vehicle may meet
    # the floor this fast at most: 1.0 m/s less the learned hover's and the motors' slack
    # (inf: unbounded)
    blind_s: float = 2.5
    blind_brake_mps2: float = 1.0
    blind_touchdown_mps: float = 0.8
    # A climb gets this many times the braking that stops it this far over the setpoint:
    # lossy-link holds (60 seeds a profile) stay within ±0.1 m and take-offs (20) within 3.3 %;
    # braked twice over, 2 of 17 000 steady-hold ticks still asked for a blind touchdown above
    # 1.0 m/s (bench/blind_risk.py)
    blind_band_m: float = 0.1
    blind_brake_factor: float = 1.5
    # a sink faster than this opens the bound, by twice it to the PID's own limit
    blind_steady_mps: float = 0.15

    def __post_init__(self) -> None:
        if not 0.0 < self.degraded_after_s < self.lost_after_s:
            raise ValueError("need 0 < degraded_after_s < lost_after_s")
        if min(self.blind_s, self.blind_band_m, self.blind_steady_mps,
               self.blind_touchdown_mps, self.land_speed_mps, self.disarm_report_s) <= 0.0:
            raise ValueError("blind_s, blind_band_m, blind_steady_mps, blind_touchdown_mps, "
                             "land_speed_mps and disarm_report_s must be > 0")
        if self.blind_brake_factor < 1.0:
            raise ValueError("blind_brake_factor must be >= 1 (it brakes a climb at least as "
                             f"hard as stopping it needs), got {self.blind_brake_factor}")
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and v < 0.0:
                raise ValueError(f"{f.name} must be >= 0, got {v}")

    def link_health(self, frame_age_s: float) -> LinkHealth:
        """What a silence of `frame_age_s` since the vehicle's last frame means (see above)."""
        if frame_age_s > self.lost_after_s:
            return LinkHealth.LOST
        if frame_age_s > self.degraded_after_s:
            return LinkHealth.DEGRADED
        return LinkHealth.OK

    def blind(self, max_mps2: float) -> BlindFlight:
        """The blind-flight envelope, for a hold that asks at most `max_mps2`."""
        return BlindFlight(self.blind_s, self.blind_brake_mps2, self.blind_touchdown_mps,
                           max_mps2, self.blind_steady_mps, self.blind_band_m,
                           self.blind_brake_factor)

    @classmethod
    def for_dialect(cls, dialect: Dialect, **overrides: object) -> SupervisorParams:
        """The policy for one firmware (unknown: the stricter 4.x timings without force)."""
        if dialect is Dialect.APM25:
            base = cls()
        elif dialect is Dialect.COPTER4:
            base = cls(spool_s=3.0, force_disarm=True, stabilize_to_disarm=False,
                       auto_disarm_s=10.0, blind_s=3.0)
        else:
            base = cls(spool_s=3.0, auto_disarm_s=10.0, blind_s=3.0)
        return dataclasses.replace(base, **overrides)  # type: ignore[arg-type]
