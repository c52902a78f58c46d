"""The autopilot of one simulated vehicle: ArduCopter's STABILIZE, ALT_HOLD, LAND and (with a
GPS) RTL / SmartRTL, arming, radio with GCS overrides, GCS, radio and battery failsafes, 4.x
motor spool-up. Pure: sensors and time go in, motor outputs come out; the MAVLink side lives in
`sitl.link`. The per-firmware rules and the facts behind them are in `arming.py`,
`failsafe.py`, `failsafe_rules.py`, `rtl.py` and `spool.py`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from sitl.autopilot import arming
from sitl.autopilot.ahrs import GRAVITY_MSS, Ahrs
from sitl.autopilot.alt_hold import (
    SHAPE_APM25,
    SHAPE_COPTER4,
    AltitudeController,
    SurfaceTracker,
)
from sitl.autopilot.arming import CommandResult, MavResult, Severity
from sitl.autopilot.attitude import AttitudeController
from sitl.autopilot.failsafe import BatteryWatch, GcsWatch, RadioWatch, ThrottleLowWatch
from sitl.autopilot.failsafe_run import run_failsafes
from sitl.autopilot.gains import Gains
from sitl.autopilot.inertial_nav import InertialNavZ
from sitl.autopilot.land_detector import LandDetector
from sitl.autopilot.mixer import MixerOutput, mix_plus
from sitl.autopilot.mode_run import ModeRunner
from sitl.autopilot.params import FS_GCS_TIMEOUT_RANGE_S, Key, ParamStore
from sitl.autopilot.profile import (
    KNOWN_UNSUPPORTED_MODES,
    AutopilotOptions,
    FlightMode,
    Profile,
)
from sitl.autopilot.radio import Radio
from sitl.autopilot.rtl import Rtl, RtlParams
from sitl.autopilot.spool import Spool
from sitl.autopilot.state import AutopilotState, SensorSample, SystemStatus

GYRO_CAL_S = 1.0  # boot-time gyro calibration of the attitude estimator
# The accelerometer range each firmware configures (3.2.1's MPU-6000 driver: ±8 g; 4.x: ±16 g),
# whatever the ±2 g the station's RAW_IMU is scaled to: a 4 m/s floor impact (≈ 10 g over a
# 10 ms loop) reaches the estimator, which clipped at 2 g went on believing it fell for seconds.
ACC_RANGE_G = {Profile.APM25: 8.0, Profile.COPTER4: 16.0}
LAND_PAUSE_S = 4.0  # LAND_WITH_DELAY_MS of both firmwares


class Autopilot(ModeRunner):
    """ArduCopter-like flight controller for one vehicle."""

    def __init__(
        self,
        profile: Profile,
        params: ParamStore,
        hover_throttle: float,
        options: AutopilotOptions | None = None,
    ) -> None:
        self.profile = profile
        self.options = options or AutopilotOptions()
        self.params = params
        if profile is Profile.APM25:
            params.set_key(Key.THR_HOVER, round(hover_throttle * 1000.0))
        else:
            params.set_key(Key.THR_HOVER, hover_throttle)
        self._param_version = -1
        self.gains = Gains.from_params(params)
        self.radio = Radio(profile, self.options.rc_input)
        self.rtl = Rtl()
        self.ahrs = Ahrs()
        # 3.2.1's inertial nav compares the baro with its estimate 150 ms back, hard-coded (its
        # fixture's overshoots need that); 4.x's EKF waits EK3_HGT_DELAY 60 ms (at 150 ms,
        # 4.x's stick steps ring and settle 10 % slow against its fixture)
        baro_delay_s = 0.15 if profile is Profile.APM25 else 0.06
        self.inav = InertialNavZ(self.gains.inav_tc_z_s, delay_s=baro_delay_s)
        self.attitude = AttitudeController(self.gains)
        shape = SHAPE_APM25 if profile is Profile.APM25 else SHAPE_COPTER4
        self.alt_ctrl = AltitudeController(self.gains, hover_throttle, shape)
        self.surface = SurfaceTracker()
        self.land = LandDetector(climb_max_ms=0.4 if profile is Profile.APM25 else 1.0)
        self.gcs = GcsWatch()
        self.radio_watch = RadioWatch()
        self.throttle_low = ThrottleLowWatch()
        self.throttle_up_s = 0.0  # when the throttle stick was last above zero
        self.battery = BatteryWatch()
        self.spool = Spool()
        self.state = AutopilotState()
        self.texts: list[tuple[int, str]] = []
        self._timed_texts = arming.boot_texts(profile, self.options)
        self._arming_until_s: float | None = None  # 3.2.1: arming in progress until then
        self.arm_completed: CommandResult | None = None  # a pending arm's answer, once
        self._want_thrust = False
        self._land_pause_until_s = 0.0
        self._t_s = 0.0
        self._zero_throttle_s = 0.0
        self._last_throttle = 0.0
        self._cal_sum = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        self._cal_n = 0
        self._acc_offset = (0.0, 0.0, 0.0)
        self._acc_lsb = ACC_RANGE_G[profile] * GRAVITY_MSS / 32768.0
        self._acc_max = 32767.0 * self._acc_lsb
        self.calibrated = False
        self._refresh_gains()

    # ---- parameters ------------------------------------------------------------------------
    def _refresh_gains(self) -> None:
        if self.params.version == self._param_version:
            return
        self._param_version = self.params.version
        self.gains = Gains.from_params(self.params)
        k = self.params.k
        apm = self.profile is Profile.APM25
        self._rc_override_time_s = k(Key.RC_OVERRIDE_TIME)
        lo, hi = FS_GCS_TIMEOUT_RANGE_S
        timeout = k(Key.FS_GCS_TIMEOUT_S)
        self._gcs_timeout_s = timeout if apm else min(hi, max(lo, timeout))
        self._disarm_delay_s = k(Key.DISARM_DELAY_S)
        self._spool_time_s = k(Key.SPOOL_TIME_S)
        self._spin_arm = min(0.3, max(0.0, k(Key.SPIN_ARM)))
        # the dead zones the vehicle reports are the ones it applies (3.2.1: 30/30/30/40 µs;
        # 4.7: 20/20/30/20), so a station that reads them flies the sticks it expects
        self._dz_us = tuple(max(0, min(400, round(k(key))))
                            for key in (Key.RC1_DZ, Key.RC2_DZ, Key.RC3_DZ, Key.RC4_DZ))
        self._thr_hover_param = k(Key.THR_HOVER)
        self._thr_min_param = k(Key.THR_MIN)
        self._rtl_params = RtlParams(
            rtl_alt_cm=k(Key.RTL_ALT_CM),
            loiter_ms=k(Key.RTL_LOIT_TIME_MS),
            speed_cms=k(Key.WP_SPEED_CMS),
            speed_up_cms=k(Key.WP_SPEED_UP_CMS),
            speed_dn_cms=k(Key.WP_SPEED_DN_CMS),
            land_speed_cms=k(Key.LAND_SPEED),
            home_distance_m=self.options.home_distance_m,
        )
        self._speed_dn_cms = k(Key.PILOT_SPEED_DN)
        self.attitude.set_gains(self.gains)
        self.alt_ctrl.set_gains(self.gains)
        self.inav.tc_z_s = self.gains.inav_tc_z_s

    # ---- GCS-facing commands --------------------------------------------------------------
    def gcs_seen(self, t_s: float) -> None:
        """A heartbeat or override arrived from the GCS system id."""
        self.gcs.seen(t_s)

    def rc_override(self, values: Sequence[int], t_s: float) -> None:
        """Apply an accepted RC_CHANNELS_OVERRIDE (it resets the GCS timer in both firmwares)."""
        self.radio.apply_override(values, t_s)
        self.radio_watch.input(t_s)
        self.gcs_seen(t_s)

    def set_mode(self, number: int) -> CommandResult:
        """Change flight mode as ArduCopter's set_mode would (RTL and SmartRTL need a GPS)."""
        try:
            mode = FlightMode(number)
        except ValueError:
            mode = None
        needs_gps = mode in (FlightMode.RTL, FlightMode.SMART_RTL)
        if (mode is None or (needs_gps and not self.options.gps)
                or (mode is FlightMode.SMART_RTL and self.profile is Profile.APM25)):
            name = KNOWN_UNSUPPORTED_MODES.get(number, str(number))
            text = None if self.profile is Profile.APM25 else "Flight mode change failed"
            return CommandResult(False, text if name else None, MavResult.FAILED)
        if mode is not self.state.mode:
            self.enter_mode(mode)
        return CommandResult(True)

    def land_with_pause(self) -> None:
        """A failsafe's LAND (set_mode_land_with_pause, both firmwares): hold the height for
        LAND_WITH_DELAY_MS (4 s), so a pilot can take over, then descend."""
        self.enter_mode(FlightMode.LAND)
        self._land_pause_until_s = self._t_s + LAND_PAUSE_S

    def enter_mode(self, mode: FlightMode) -> None:
        """Switch to `mode` (the controllers start from the current height and climb)."""
        if mode is not FlightMode.STABILIZE:
            self.alt_ctrl.reset(
                self.inav.alt_m * 100.0, self._last_throttle, self.inav.climb_ms * 100.0
            )
        # 3.2.1's surface tracking re-aims when it has not run for a second (SONAR_TIMEOUT_MS):
        # a mode change stands for that
        self.surface.target_cm = None
        if mode in (FlightMode.RTL, FlightMode.SMART_RTL):
            self.rtl.start(self.inav.alt_m * 100.0, self._t_s, self._rtl_params,
                           smart=mode is FlightMode.SMART_RTL)
        self.state.mode = mode
        self._land_pause_until_s = 0.0

    @property
    def arming_in_progress(self) -> bool:
        """3.2.1 is inside init_arm_motors(): main loop blocked, streams paused."""
        return self._arming_until_s is not None

    def arm(self, force: float = 0.0) -> CommandResult:
        """MAV_CMD_COMPONENT_ARM_DISARM param1 = 1."""
        if self.arming_in_progress:
            return arming.refused(self.profile, None)
        if self.state.armed:
            return CommandResult(True)
        st = self.state
        if st.mode is FlightMode.STABILIZE:
            throttle_up = self.throttle_stick() > 0.0
        else:
            throttle_up = self._pilot_climb_cms() > 0.0
        refusal = arming.arm_check(
            self.profile, self.options, self._t_s, st.mode, throttle_up, force
        )
        if refusal is not None:
            return refusal
        if self.profile is Profile.APM25:
            t = self._t_s
            self._arming_until_s = t + arming.APM25_ARMING_S
            texts = arming.apm25_arming_texts()
            self._timed_texts += [(t + dt, sev, text) for dt, sev, text in texts]
            return CommandResult(True, pending=True)
        self._do_arm()
        self.texts.append((int(Severity.INFO), "Arming motors"))
        return CommandResult(True)

    def _do_arm(self) -> None:
        self.state.armed = True
        self.land.landed = True
        self.spool.arm(self._t_s)
        self.attitude.relax(self.state.yaw_rad)
        self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)

    def disarm(self, force: float = 0.0) -> CommandResult:
        """MAV_CMD_COMPONENT_ARM_DISARM param1 = 0."""
        if not self.state.armed:
            return CommandResult(True)
        refusal = arming.disarm_check(self.profile, self.state.mode, self.land.landed, force)
        if refusal is not None:
            return refusal
        self._disarm()
        return CommandResult(True)

    def force_disarm(self) -> None:
        """Disarm whatever the mode (a failsafe's disarm)."""
        self._disarm()

    def version_texts(self) -> list[tuple[int, str]]:
        """The texts the firmware sends on PARAM_REQUEST_LIST."""
        return arming.version_texts(self.profile, self.options)

    def autopilot_version(self) -> tuple[int, bytes] | None:
        """AUTOPILOT_VERSION's version number and git hash; None where there is none (3.2.1)."""
        return arming.autopilot_version(self.profile, self.options)

    # ---- the main loop ---------------------------------------------------------------------
    def update(self, s: SensorSample, t_s: float, dt_s: float) -> MixerOutput:
        """One main-loop tick: estimate, check failsafes, run the mode, mix."""
        self._t_s = t_s
        self._refresh_gains()
        self._due_texts(t_s)
        if self._arming_until_s is not None and t_s + 1e-9 >= self._arming_until_s:
            self._arming_until_s = None
            self._do_arm()
            self.arm_completed = CommandResult(True)
        st = self.state
        g = self.gains
        if not self.calibrated:
            self._calibrate(s.gyro_b, s.acc_b, t_s)
        off = self._acc_offset
        acc_b = (s.acc_b[0] - off[0], s.acc_b[1] - off[1], s.acc_b[2] - off[2])
        # The vertical navigation and the altitude controller integrate the driver's loop
        # average in the firmware's own range (sensors/imu.py); the attitude estimator keeps
        # the single sample with its whole vibration, which only makes it noisier than the
        # firmware's (and leaves every STABILIZE flight as it was).
        fw = s.acc_fw_b if s.acc_fw_b is not None else s.acc_b
        acc_v = (self._acc_counts(fw[0]) - off[0], self._acc_counts(fw[1]) - off[1],
                 self._acc_counts(fw[2]) - off[2])
        self.ahrs.update(s.gyro_b, acc_b, dt_s)
        roll, pitch, yaw = self.ahrs.euler()
        st.roll_rad, st.pitch_rad, st.yaw_rad = roll, pitch, yaw
        st.gyro_rads = self.ahrs.gyro_corrected
        tilt_cos = math.cos(roll) * math.cos(pitch)
        f_n = self.ahrs.body_to_ned(acc_v)
        acc_up = -(f_n[2] + GRAVITY_MSS)
        if s.baro_alt_m is not None:
            self.inav.correct(s.baro_alt_m)
        self.inav.update(acc_up, dt_s)
        if s.sonar_fresh:
            self.surface.reading(s.sonar_m, tilt_cos, g)

        # 4.x drops overrides after RC_OVERRIDE_TIME (0 = never, 3.2.1's behaviour)
        self.radio.expire(t_s, self._rc_override_time_s)
        run_failsafes(self, t_s, s.battery_v, self._gcs_timeout_s)

        throttle, t_roll, t_pitch, yaw_rate = self._run_mode(dt_s, acc_up, tilt_cos)
        if self.profile is Profile.COPTER4:
            self.spool.update(t_s, dt_s, self._spool_time_s, st.armed and self._want_thrust)
            idle, thrust_max = self.spool.idle_ratio, self.spool.thrust_max
        else:
            idle = thrust_max = 1.0
        spin = self._spin_arm
        if not st.armed or idle < 1.0:
            # disarmed, or 4.x's arming delay / spool to ground idle: no control authority
            self.attitude.relax(yaw)
            level = spin * idle if st.armed else 0.0
            out = MixerOutput((level,) * 4, False, True)
            throttle = 0.0
        elif throttle <= 0.0 or thrust_max <= 0.0:
            self.attitude.relax(yaw)
            out = mix_plus(spin, 0.0, 0.0, 0.0, spin)
            throttle = 0.0
        else:
            throttle = min(throttle, thrust_max)
            att = self.attitude.update(
                t_roll,
                t_pitch,
                yaw_rate,
                (roll, pitch, yaw),
                st.gyro_rads,
                dt_s,
                saturated=st.motors.limit_high,
            )
            out = mix_plus(throttle, att.roll, att.pitch, att.yaw, max(spin, g.thr_min))
        self._last_throttle = throttle
        st.throttle = throttle
        st.motors = out
        st.alt_m = self.inav.alt_m
        st.climb_ms = self.inav.climb_ms
        st.target_alt_m = self.alt_ctrl.target_alt_cm / 100.0
        self._post_tick(throttle, dt_s)
        return out

    def _due_texts(self, t_s: float) -> None:
        due = [x for x in self._timed_texts if x[0] <= t_s + 1e-9]
        if due:
            self._timed_texts = [x for x in self._timed_texts if x[0] > t_s + 1e-9]
            self.texts.extend((sev, text) for _, sev, text in due)

    def _acc_counts(self, a_mss: float) -> float:
        """The firmware's accelerometer reading: its own range's LSB, saturated."""
        lsb = self._acc_lsb
        a = round(a_mss / lsb) * lsb
        return a if -self._acc_max <= a <= self._acc_max else math.copysign(self._acc_max, a)

    def _calibrate(
        self, gyro_b: tuple[float, float, float], acc_b: tuple[float, float, float], t_s: float
    ) -> None:
        for i in range(3):
            self._cal_sum[i] += gyro_b[i]
            self._cal_sum[3 + i] += acc_b[i]
        self._cal_n += 1
        if t_s + 1e-9 >= GYRO_CAL_S:
            n = float(self._cal_n)
            self.ahrs.set_gyro_offsets(
                (self._cal_sum[0] / n, self._cal_sum[1] / n, self._cal_sum[2] / n)
            )
            mean_acc = (self._cal_sum[3] / n, self._cal_sum[4] / n, self._cal_sum[5] / n)
            # The owner's accelerometer calibration and "calibrate level" (AHRS_TRIM): the
            # vehicle boots standing level, so what the accelerometer reads beyond (0, 0, -g)
            # at rest is its offset.
            self._acc_offset = (mean_acc[0], mean_acc[1], mean_acc[2] + GRAVITY_MSS)
            self.ahrs.level_from((0.0, 0.0, -GRAVITY_MSS), 0.0)
            self.calibrated = True

    @property
    def booting(self) -> bool:
        """4.x's first seconds: HEARTBEAT base_mode 89, system_status BOOT (3.2.1 has neither)."""
        return self.profile is Profile.COPTER4 and self._t_s < arming.COPTER4_BOOT_S

    @property
    def system_status(self) -> SystemStatus:
        """Follows the land detector as both firmwares do: STANDBY landed, ACTIVE flying,
        CRITICAL in a failsafe; 4.x BOOT at first, 3.2.1 ACTIVE until its land detector runs."""
        st = self.state
        if self.booting:
            return SystemStatus.BOOT
        if st.gcs_failsafe or st.battery_failsafe or st.radio_failsafe:
            return SystemStatus.CRITICAL
        if self.profile is Profile.APM25 and self._t_s < arming.APM25_FIRST_LANDED_S:
            return SystemStatus.ACTIVE
        return SystemStatus.STANDBY if st.landed else SystemStatus.ACTIVE
