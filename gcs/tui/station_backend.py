"""Feeds the teleop screen from a live `Station` and hands the pilot's intents to it.

The station's loop thread calls `_on_tick` after every tick; it only appends to bounded deques
(and steps the thesis's eq. 6.1 observer beside the station's own, for the "accel" row), so it
costs microseconds. The UI thread builds views from those deques at its redraw rate.
"""

from __future__ import annotations

import math
import threading
from collections import deque

from firmware_link.forward import ForwardPort
from firmware_link.records import Battery, FlightMode, Rangefinder, SystemStatus
from gcs.estimation import DeadReckoningEstimator
from gcs.pilot import intents
from gcs.pilot.view import AltitudeView, LinkView, LoopView, TeleopView, VehicleView
from gcs.station.station import ControlMode, Station, StationSnapshot
from gcs.tui.sticks import stick_to_pwm

HISTORY_S = 30.0
HISTORY_EVERY_TICKS = 4  # 10 Hz of plot points at the 25 ms loop: two per column is plenty
MODE_NAMES = {m.value: m.name for m in FlightMode}
MAX_SETPOINT_M = 3.5  # the sonar's trustworthy range
SETPOINT_RATE_MPS = 0.5


class StationBackend:
    """A `TeleopBackend` over a running station."""

    live = True

    def __init__(self, station: Station, *, url: str = "", recording: str | None = None,
                 dialect: str = "", signing: bool = False,
                 forward: ForwardPort | None = None, firmware: str = "",
                 firmware_source: str = "") -> None:
        self.station = station
        self.url = url
        self.recording = recording
        self.dialect = dialect
        self.firmware = firmware
        self.firmware_source = firmware_source
        self.signing = signing
        self.forward = forward  # the forwarded stations' side of the link (None: no --forward)
        n = int(HISTORY_S / (station.config.period_s * HISTORY_EVERY_TICKS))
        self._alt: deque[tuple[float, float | None, float | None, float | None]] = deque(maxlen=n)
        self._acc: deque[tuple[float, float | None]] = deque(maxlen=n)
        self._baseline = DeadReckoningEstimator(station.config.estimator)
        self._baseline_alt: float | None = None
        self._last_sonar_t = -math.inf
        self._lock = threading.Lock()
        self._t0 = station.snapshot().t_s
        self._truth_m: float | None = None
        self._target_m: float | None = None  # where the pilot has put the hold setpoint
        self._notes: tuple[tuple[float, str], ...] = (
            (0.0, f"recording to {recording}") if recording else (0.0, "not recording"),
        )
        station.add_listener(self._on_tick)

    # --- loop thread -----------------------------------------------------------------------

    def _on_tick(self, snap: StationSnapshot) -> None:
        sonar = snap.rangefinder
        fresh_sonar: Rangefinder | None = None
        if sonar is not None and sonar.t_s > self._last_sonar_t:
            self._last_sonar_t = sonar.t_s
            fresh_sonar = sonar
        if not snap.armed:
            # the thesis's dead reckoning starts at take-off: on the ground it would only
            # integrate accelerometer bias into metres
            if self._baseline_alt is not None:
                self._baseline = DeadReckoningEstimator(self.station.config.estimator)
                self._baseline_alt = None
        else:
            self._baseline_alt = self._baseline.update(snap.imu, fresh_sonar, snap.attitude,
                                                       snap.t_s).alt_m
        if snap.truth is not None and math.isfinite(snap.truth.pos_n[2]):
            self._truth_m = -snap.truth.pos_n[2]  # SIMSTATE has no altitude; SIM_STATE has
        if snap.tick % HISTORY_EVERY_TICKS:
            return
        est = snap.estimate
        sonar_m = sonar.distance_m if sonar is not None and sonar.valid else None
        with self._lock:
            self._alt.append((snap.t_s, est.alt_m if est else None, snap.alt_setpoint_m, sonar_m))
            self._acc.append((snap.t_s, est.acc_mps2 if est else None))

    # --- UI thread -------------------------------------------------------------------------

    def view(self) -> TeleopView:
        """Build the view from the latest snapshot and the histories."""
        snap = self.station.snapshot()
        with self._lock:
            alt_hist, acc_hist = tuple(self._alt), tuple(self._acc)
        hb = snap.heartbeat
        stats = snap.link_stats
        battery = snap.latest.get(Battery)
        battery = battery if isinstance(battery, Battery) else None
        est, att = snap.estimate, snap.attitude
        sonar = snap.rangefinder
        loop = snap.loop
        fwd = self.forward.stats if self.forward is not None else None
        return TeleopView(
            t_s=snap.t_s,
            link=LinkView(
                url=self.url,
                dialect=self.dialect,
                firmware=self.firmware,
                firmware_source=self.firmware_source,
                connected=hb is not None,
                lost=snap.link_lost,
                heartbeat_age_s=snap.t_s - hb.t_s if hb is not None else None,
                msgs_per_s=stats.rx_messages_per_s,
                rx_lost=stats.lost_messages,
                rx_bad=stats.bad_frames + stats.signature_refusals,
                signing=self.signing,
                recording=self.recording,
                fwd_stations=fwd.stations if fwd is not None else None,
                fwd_refused_overrides=fwd.refused_overrides if fwd is not None else 0,
            ),
            vehicle=VehicleView(
                mode=MODE_NAMES.get(snap.vehicle_mode, str(snap.vehicle_mode))
                if snap.vehicle_mode >= 0 else "",
                armed=snap.armed,
                failsafe=hb is not None and hb.system_status >= SystemStatus.CRITICAL,
                battery_v=battery.voltage_v if battery is not None else None,
                battery_pct=battery.remaining_pct if battery is not None else None,
                roll_deg=math.degrees(att.roll_rad) if att else None,
                pitch_deg=math.degrees(att.pitch_rad) if att else None,
                yaw_deg=math.degrees(att.yaw_rad) if att else None,
            ),
            altitude=AltitudeView(
                sonar_m=sonar.distance_m if sonar is not None and sonar.valid else None,
                accel_m=self._baseline_alt,
                fused_m=est.alt_m if est else None,
                setpoint_m=snap.alt_setpoint_m,
                climb_mps=est.vel_mps if est else None,
                acc_up_mps2=est.acc_mps2 if est else None,
                truth_m=self._truth_m,
                hold_on=snap.mode in (ControlMode.ALT_HOLD, ControlMode.POSITION),
                throttle_us=snap.command.throttle_us,
            ),
            loop=LoopView(
                period_ms=loop.period_mean_s * 1e3 if loop.ticks else None,
                jitter_p99_ms=loop.jitter_p99_s * 1e3 if loop.ticks else None,
                compute_ms=loop.compute_p99_s * 1e3 if loop.ticks else None,
                overruns=loop.overruns,
                ticks=loop.ticks,
            ),
            alt_history=alt_hist,
            acc_history=acc_hist,
            messages=self._notes + tuple((e.t_s - self._t0, e.text) for e in snap.events),
            replay=None,
        )

    def send(self, intent: intents.Intent) -> None:
        """Translate a UI intent into a station intent (queued for the loop thread)."""
        st = self.station
        match intent:
            case intents.Arm():
                st.request_arm()
            case intents.Disarm():
                st.request_disarm()
            case intents.Kill():
                st.kill()
            case intents.SetMode(mode=name):
                st.set_mode(FlightMode[name])
            case intents.Sticks(roll=r, pitch=p, yaw=y, throttle_us=thr):
                # ArduCopter: pitch stick low = nose down = forward, so "forward" lowers RC2
                st.set_sticks(stick_to_pwm(r), stick_to_pwm(-p), stick_to_pwm(y), thr)
            case intents.AltHold(on=on):
                self._target_m = None
                st.alt_hold(on)
            case intents.SetpointStep(delta_m=d):
                # keys arrive faster than the loop applies them: step from our own target
                snap = st.snapshot()
                if self._target_m is None:
                    base = snap.alt_setpoint_m
                    if base is None:
                        base = snap.estimate.alt_m if snap.estimate else 0.0
                    self._target_m = base
                self._target_m = min(max(self._target_m + d, 0.0), MAX_SETPOINT_M)
                st.alt_hold(True, self._target_m, SETPOINT_RATE_MPS)
            case _:
                pass  # replay-only intents mean nothing to a live vehicle

    def close(self) -> None:
        """Stop the loop; it releases the overrides on its way out."""
        self.station.stop()
