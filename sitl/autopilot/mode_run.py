"""What the flight mode makes of the pilot's sticks each tick, for `Autopilot` (its base class):
the sticks past their dead zones, the throttle and attitude targets of STABILIZE, ALT_HOLD, LAND
and RTL / SmartRTL, and after the tick the land detector and the disarms it leads to.
"""

from __future__ import annotations

import math

from sitl.autopilot import arming
from sitl.autopilot.alt_hold import AltitudeController, SurfaceTracker
from sitl.autopilot.gains import Gains
from sitl.autopilot.inertial_nav import InertialNavZ
from sitl.autopilot.land_detector import LandDetector
from sitl.autopilot.pilot_climb import climb_rate_apm25, climb_rate_copter4
from sitl.autopilot.profile import FlightMode, Profile
from sitl.autopilot.radio import Radio
from sitl.autopilot.rtl import Rtl, RtlParams
from sitl.autopilot.spool import Spool
from sitl.autopilot.state import AutopilotState
from sitl.autopilot.throttle_curve import throttle_apm25, throttle_copter4

SURFTRAK_TC_S = 1.0  # 4.x SURFTRAK_TC


class ModeRunner:
    """The autopilot's state these methods read and write is declared here and set by
    `Autopilot.__init__` and `Autopilot._refresh_gains`."""

    profile: Profile
    gains: Gains
    radio: Radio
    state: AutopilotState
    alt_ctrl: AltitudeController
    inav: InertialNavZ
    rtl: Rtl
    land: LandDetector
    surface: SurfaceTracker
    spool: Spool
    texts: list[tuple[int, str]]
    _dz_us: tuple[int, ...]
    _thr_min_param: float
    _thr_hover_param: float
    _speed_dn_cms: float
    _disarm_delay_s: float
    _rtl_params: RtlParams
    _t_s: float
    _want_thrust: bool
    _land_pause_until_s: float
    _last_throttle: float
    _zero_throttle_s: float

    # ---- sticks ----------------------------------------------------------------------------
    def throttle_stick(self) -> float:
        """Throttle channel as control_in, 0..1000, with the bottom dead zone."""
        pwm = self.radio.channel(2)
        dz = self._dz_us[2]
        c = (pwm - 1000.0 - dz) * 1000.0 / (1000.0 - dz)  # min(1000, max(0, c)), no calls
        c = c if c > 0.0 else 0.0
        return c if c < 1000.0 else 1000.0

    def _centred(self, ch: int) -> float:
        """A centred stick past its dead zone, -1..1."""
        d = self.radio.channel(ch) - 1500
        dz = self._dz_us[ch]
        if abs(d) <= dz:
            return 0.0
        d -= int(math.copysign(dz, d))
        return d / (500.0 - dz)

    def _angle(self, ch: int) -> float:
        return self._centred(ch) * self.gains.angle_max_rad

    def _yaw_rate(self) -> float:
        return self._centred(3) * self.gains.pilot_yaw_rate_max_rads

    def _pilot_climb_cms(self) -> float:
        g = self.gains
        pwm = self.radio.channel(2)
        if self.profile is Profile.APM25:
            return climb_rate_apm25(
                pwm, self._dz_us[2], round(g.thr_dz), round(self._thr_min_param),
                round(g.pilot_velz_max_cms),
            )
        return climb_rate_copter4(
            pwm, self._dz_us[2], round(g.thr_dz), g.pilot_velz_max_cms, self._speed_dn_cms
        )

    # ---- the mode's targets, and after the tick ------------------------------------------
    def _run_mode(
        self, dt_s: float, acc_up: float, tilt_cos: float
    ) -> tuple[float, float, float, float]:
        st = self.state
        c4 = self.profile is Profile.COPTER4
        t_roll = self._angle(0)
        t_pitch = self._angle(1)
        yaw_rate = self._yaw_rate()
        # LAND without GPS takes no pilot input under a radio failsafe (land_nogps_run: `if
        # (!failsafe.radio)`): a dead uplink's last override must not keep the vehicle leaning;
        # RTL and SmartRTL fly themselves
        rtl = st.mode in (FlightMode.RTL, FlightMode.SMART_RTL)
        if rtl or (st.mode is FlightMode.LAND and st.radio_failsafe):
            t_roll = t_pitch = yaw_rate = 0.0
        if st.mode is FlightMode.STABILIZE:
            stick = self.throttle_stick()
            self._want_thrust = stick > 0.0
            if not c4:
                thr = throttle_apm25(stick, self._thr_hover_param, self._thr_min_param)
            else:
                thr = throttle_copter4(stick, self.alt_ctrl.hover_throttle)
            if not st.armed:
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
            return thr, t_roll, t_pitch, yaw_rate
        if rtl:
            climb = self.rtl.climb_rate(self.inav.alt_m * 100.0, self._t_s, self._rtl_params)
            self._want_thrust = climb > 0.0 or not self.land.landed
            if not st.armed or (self.land.landed and climb <= 0.0):
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
                return 0.0, t_roll, t_pitch, yaw_rate
            if self.land.landed and self._last_throttle <= 0.0:
                self.alt_ctrl.init_takeoff(self.inav.alt_m * 100.0)
            out = self.alt_ctrl.update(
                climb, self.inav.alt_m * 100.0, self.inav.climb_ms * 100.0, acc_up * 100.0,
                dt_s, tilt_cos,
            )
            self.alt_ctrl.learn_hover(out.throttle * tilt_cos, self.inav.climb_ms, dt_s)
            return out.throttle, t_roll, t_pitch, yaw_rate
        if st.mode is FlightMode.ALT_HOLD:
            climb = self._pilot_climb_cms()
            self._want_thrust = climb > 0.0 or not self.land.landed
            # 4.x takes off only once the motors have spooled up (takeoff.triggered)
            waiting = c4 and self.land.landed and not self.spool.unlimited
            if not st.armed or (self.land.landed and climb <= 0.0) or waiting:
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
                return 0.0, t_roll, t_pitch, yaw_rate
            if self.land.landed and self._last_throttle <= 0.0:
                self.alt_ctrl.init_takeoff(self.inav.alt_m * 100.0)
        else:  # LAND
            paused = self._t_s < self._land_pause_until_s and not self.land.landed
            climb = 0.0 if paused else -self.gains.land_speed_cms
            self._want_thrust = not self.land.landed
            if not st.armed or self.land.landed:
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
                return 0.0, t_roll, t_pitch, yaw_rate
        if c4:
            self.alt_ctrl.target_alt_cm += self.surface.terrain_shift(
                self.inav.alt_m * 100.0, dt_s, SURFTRAK_TC_S
            )
        else:
            climb = self.surface.climb_rate(
                climb,
                dt_s,
                self.gains.rng_gain,
                self.alt_ctrl.target_alt_cm,
                self.inav.alt_m * 100.0,
            )
        out = self.alt_ctrl.update(
            climb,
            self.inav.alt_m * 100.0,
            self.inav.climb_ms * 100.0,
            acc_up * 100.0,
            dt_s,
            tilt_cos,
        )
        self.alt_ctrl.learn_hover(out.throttle * tilt_cos, self.inav.climb_ms, dt_s)
        return out.throttle, t_roll, t_pitch, yaw_rate

    def _post_tick(self, throttle: float, dt_s: float) -> None:
        st = self.state
        if not st.armed:
            self.land.landed = True
            st.landed = True
            return
        low = throttle <= 0.0 or (self.alt_ctrl.limit_low and st.mode is not FlightMode.STABILIZE)
        touched = self.land.update(
            low, self.inav.climb_ms, throttle, self.alt_ctrl.hover_throttle, dt_s
        )
        st.landed = self.land.landed
        stick_zero = self.throttle_stick() <= 0.0
        # 3.2.1 (LAND_REQUIRE_MIN_THROTTLE_TO_DISARM) waits for the stick or the radio failsafe
        disarm_ok = self.profile is Profile.COPTER4 or stick_zero or st.radio_failsafe
        landing = st.mode is FlightMode.LAND or (
            st.mode in (FlightMode.RTL, FlightMode.SMART_RTL) and self.rtl.landing
        )
        if landing and self.land.landed and disarm_ok:
            self._disarm()
            return
        if touched:
            self._zero_throttle_s = 0.0
        # auto-disarm: landed with the stick down for DISARM_DELAY (4.x, 0 = off) or 15 s (3.2.1)
        if self.land.landed and stick_zero and self._disarm_delay_s > 0.0:
            self._zero_throttle_s += dt_s
            if self._zero_throttle_s >= self._disarm_delay_s:
                self._disarm()
        else:
            self._zero_throttle_s = 0.0

    def _disarm(self) -> None:
        self.state.armed = False
        self.spool.disarm()
        self.texts.append(arming.disarm_text(self.profile))
