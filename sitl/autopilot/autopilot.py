"""The autopilot of one simulated vehicle: ArduCopter's STABILIZE, ALT_HOLD and LAND, arming,
radio with GCS overrides, GCS and battery failsafes. Pure: sensors and time go in, motor
outputs come out; the MAVLink side lives in `sitl.link`.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from sitl.autopilot.ahrs import GRAVITY_MSS, Ahrs
from sitl.autopilot.alt_hold import AltitudeController, SurfaceTracker
from sitl.autopilot.attitude import AttitudeController
from sitl.autopilot.failsafe import BatteryWatch, GcsFailsafeAction, GcsWatch
from sitl.autopilot.gains import Gains
from sitl.autopilot.inertial_nav import InertialNavZ
from sitl.autopilot.land_detector import LandDetector
from sitl.autopilot.mixer import MixerOutput, mix_plus
from sitl.autopilot.params import Key, ParamStore
from sitl.autopilot.profile import KNOWN_UNSUPPORTED_MODES, FlightMode, Profile
from sitl.autopilot.radio import Radio
from sitl.autopilot.throttle_curve import (
    climb_rate_from_stick,
    throttle_apm25,
    throttle_copter4,
)

FORCE_ARM_MAGIC = 2989.0
FORCE_DISARM_MAGIC = 21196.0
STICK_DZ_US = 30  # RCn_DZ for roll/pitch
YAW_DZ_US = 40
GYRO_CAL_S = 1.0  # boot-time gyro calibration; arming is refused until it is done
AUTO_DISARM_S = {Profile.APM25: 15.0, Profile.COPTER4: 10.0}
SPIN_ARMED = {Profile.APM25: 0.07, Profile.COPTER4: 0.10}  # MOT_SPIN_ARMED 70 / MOT_SPIN_ARM
BOOT_TEXTS = {
    Profile.APM25: ("Initialising APM...", "APM:Copter V3.2.1", "Frame: PLUS"),
    Profile.COPTER4: ("ArduCopter V4.5.7", "Frame: QUAD/PLUS"),
}


class Severity(enum.IntEnum):
    """MAV_SEVERITY values used in STATUSTEXT."""

    CRITICAL = 2
    ERROR = 3
    WARNING = 4
    NOTICE = 5
    INFO = 6


class SystemStatus(enum.IntEnum):
    """MAV_STATE values the heartbeat reports."""

    BOOT = 1
    STANDBY = 3
    ACTIVE = 4
    CRITICAL = 5


@dataclass(frozen=True)
class SensorSample:
    """What the autopilot's sensors delivered this tick (SI, body FRD)."""

    gyro_b: tuple[float, float, float]
    acc_b: tuple[float, float, float]  # specific force, m/s²
    baro_alt_m: float | None = None  # new barometric altitude, up positive
    sonar_m: float | None = None  # sonar distance of a new reading, None if it had no echo
    sonar_fresh: bool = False  # a sonar reading (with or without echo) arrived this tick
    battery_v: float = 12.6


@dataclass(frozen=True)
class CommandResult:
    """Outcome of a GCS command; `text` goes out as STATUSTEXT when set."""

    accepted: bool
    text: str | None = None


@dataclass
class AutopilotState:
    """What telemetry reports; refreshed every tick."""

    armed: bool = False
    mode: FlightMode = FlightMode.STABILIZE
    roll_rad: float = 0.0
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    gyro_rads: tuple[float, float, float] = (0.0, 0.0, 0.0)
    alt_m: float = 0.0
    climb_ms: float = 0.0
    throttle: float = 0.0
    target_alt_m: float = 0.0
    motors: MixerOutput = field(default_factory=lambda: MixerOutput((0.0,) * 4, False, False))
    landed: bool = True
    gcs_failsafe: bool = False
    battery_failsafe: bool = False
    hold_for_gcs: bool = False


class Autopilot:
    """ArduCopter-like flight controller for one vehicle."""

    def __init__(self, profile: Profile, params: ParamStore, hover_throttle: float) -> None:
        self.profile = profile
        self.params = params
        if profile is Profile.APM25:
            params.set_key(Key.THR_HOVER, round(hover_throttle * 1000.0))
        else:
            params.set_key(Key.THR_HOVER, hover_throttle)
        self._param_version = -1
        self.gains = Gains.from_params(params)
        self.radio = Radio(profile)
        self.ahrs = Ahrs()
        self.inav = InertialNavZ(self.gains.inav_tc_z_s)
        self.attitude = AttitudeController(self.gains)
        self.alt_ctrl = AltitudeController(self.gains, hover_throttle)
        self.surface = SurfaceTracker()
        self.land = LandDetector(climb_max_ms=0.4 if profile is Profile.APM25 else 1.0)
        self.gcs = GcsWatch()
        self.battery = BatteryWatch()
        self.state = AutopilotState()
        self.texts: list[tuple[Severity, str]] = [
            (Severity.INFO, text) for text in BOOT_TEXTS[profile]
        ]
        self._t_s = 0.0
        self._zero_throttle_s = 0.0
        self._last_throttle = 0.0
        self._cal_sum = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        self._cal_n = 0
        self._acc_offset = (0.0, 0.0, 0.0)
        self.calibrated = False
        self._refresh_gains()

    # ---- parameters ------------------------------------------------------------------------
    def _refresh_gains(self) -> None:
        if self.params.version == self._param_version:
            return
        self._param_version = self.params.version
        self.gains = Gains.from_params(self.params)
        k = self.params.k
        self._rc_override_time_s = (
            k(Key.RC_OVERRIDE_TIME) if self.params.has_key(Key.RC_OVERRIDE_TIME) else 0.0
        )
        self._thr_hover_param = k(Key.THR_HOVER)
        self._thr_min_param = k(Key.THR_MIN)
        fs_value = int(k(Key.FS_GCS_ENABLE))
        self._fs_gcs = GcsFailsafeAction(fs_value if 0 <= fs_value <= 3 else 0)
        self._fs_batt_enabled = k(Key.FS_BATT_ENABLE) > 0
        self._fs_batt_voltage = k(Key.FS_BATT_VOLTAGE)
        self.attitude.set_gains(self.gains)
        self.alt_ctrl.set_gains(self.gains)
        self.inav.tc_z_s = self.gains.inav_tc_z_s

    # ---- sticks ----------------------------------------------------------------------------
    def _throttle_stick(self) -> float:
        """Throttle channel as control_in, 0..1000, with the bottom dead zone."""
        pwm = self.radio.channel(2)
        return min(1000.0, max(0.0, (pwm - 1000.0 - STICK_DZ_US) * 1000.0 / (1000.0 - STICK_DZ_US)))

    def _angle(self, ch: int) -> float:
        d = self.radio.channel(ch) - 1500
        if abs(d) <= STICK_DZ_US:
            return 0.0
        d -= int(math.copysign(STICK_DZ_US, d))
        return d / (500.0 - STICK_DZ_US) * self.gains.angle_max_rad

    def _yaw_rate(self) -> float:
        d = self.radio.channel(3) - 1500
        if abs(d) <= YAW_DZ_US:
            return 0.0
        d -= int(math.copysign(YAW_DZ_US, d))
        return d / (500.0 - YAW_DZ_US) * self.gains.pilot_yaw_rate_max_rads

    def _pilot_climb_cms(self) -> float:
        g = self.gains
        return climb_rate_from_stick(
            self._throttle_stick(), g.thr_dz, g.pilot_velz_max_cms, g.pilot_velz_max_cms
        )

    # ---- GCS-facing commands --------------------------------------------------------------
    def gcs_seen(self, t_s: float) -> None:
        """A heartbeat or override arrived from SYSID_MYGCS."""
        self.gcs.seen(t_s)

    def rc_override(self, values: Sequence[int], t_s: float) -> None:
        """Apply an accepted RC_CHANNELS_OVERRIDE."""
        self.radio.apply_override(values, t_s)
        if self.profile is Profile.APM25:
            self.gcs_seen(t_s)  # 3.2.1 resets its GCS timer on overrides too

    def set_mode(self, number: int) -> CommandResult:
        """Change flight mode as ArduCopter's set_mode would."""
        try:
            mode = FlightMode(number)
        except ValueError:
            name = KNOWN_UNSUPPORTED_MODES.get(number, str(number))
            text = None if self.profile is Profile.APM25 else "Flight mode change failed"
            return CommandResult(False, text if name else None)
        if mode is self.state.mode:
            return CommandResult(True)
        self._enter_mode(mode)
        return CommandResult(True)

    def _enter_mode(self, mode: FlightMode) -> None:
        if mode in (FlightMode.ALT_HOLD, FlightMode.LAND):
            self.alt_ctrl.reset(
                self.inav.alt_m * 100.0, self._last_throttle, self.inav.climb_ms * 100.0
            )
        self.state.mode = mode
        self.state.hold_for_gcs = False

    def arm(self, force: float = 0.0) -> CommandResult:
        """MAV_CMD_COMPONENT_ARM_DISARM param1 = 1."""
        if self.state.armed:
            return CommandResult(True)
        forced = self.profile is Profile.COPTER4 and force == FORCE_ARM_MAGIC
        if not self.calibrated:
            return CommandResult(False, "PreArm: Gyros not calibrated")
        if not forced:
            if self.profile is Profile.COPTER4 and self.state.mode is FlightMode.LAND:
                return CommandResult(False, "Arm: Mode not armable")
            if self.state.mode is FlightMode.STABILIZE:
                too_high = self._throttle_stick() > 0.0
            else:
                too_high = self._pilot_climb_cms() > 0.0
            if too_high:
                return CommandResult(False, "Arm: Throttle too high")
        self.state.armed = True
        self.land.landed = True
        self.attitude.relax(self.state.yaw_rad)
        self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
        self.texts.append((Severity.INFO, "Arming motors"))
        return CommandResult(True)

    def disarm(self, force: float = 0.0) -> CommandResult:
        """MAV_CMD_COMPONENT_ARM_DISARM param1 = 0 (4.x refuses in flight unless forced)."""
        if not self.state.armed:
            return CommandResult(True)
        if self.profile is Profile.COPTER4 and not self.land.landed and force != FORCE_DISARM_MAGIC:
            return CommandResult(False, "Disarm: vehicle is flying")
        self._disarm()
        return CommandResult(True)

    def _disarm(self) -> None:
        self.state.armed = False
        self.texts.append((Severity.INFO, "Disarming motors"))

    # ---- the main loop ---------------------------------------------------------------------
    def update(self, s: SensorSample, t_s: float, dt_s: float) -> MixerOutput:
        """One main-loop tick: estimate, check failsafes, run the mode, mix."""
        self._t_s = t_s
        self._refresh_gains()
        st = self.state
        g = self.gains
        if not self.calibrated:
            self._calibrate(s, t_s)
        acc_b = (
            s.acc_b[0] - self._acc_offset[0],
            s.acc_b[1] - self._acc_offset[1],
            s.acc_b[2] - self._acc_offset[2],
        )
        self.ahrs.update(s.gyro_b, acc_b, dt_s)
        roll, pitch, yaw = self.ahrs.euler()
        st.roll_rad, st.pitch_rad, st.yaw_rad = roll, pitch, yaw
        st.gyro_rads = self.ahrs.gyro_corrected
        tilt_cos = math.cos(roll) * math.cos(pitch)
        f_n = self.ahrs.body_to_ned(acc_b)
        acc_up = -(f_n[2] + GRAVITY_MSS)
        if s.baro_alt_m is not None:
            self.inav.correct(s.baro_alt_m)
        self.inav.update(acc_up, dt_s)
        if s.sonar_fresh:
            self.surface.reading(s.sonar_m, tilt_cos, g)

        if self.profile is Profile.COPTER4:
            self.radio.expire(t_s, self._rc_override_time_s)
        self._failsafes(t_s, s.battery_v)

        throttle, t_roll, t_pitch, yaw_rate = self._run_mode(dt_s, acc_up, tilt_cos)
        if not st.armed:
            self.attitude.relax(yaw)
            out = MixerOutput((0.0, 0.0, 0.0, 0.0), False, True)
            throttle = 0.0
        else:
            spin = SPIN_ARMED[self.profile]
            if throttle <= 0.0:
                self.attitude.relax(yaw)
                out = mix_plus(spin, 0.0, 0.0, 0.0, spin)
            else:
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

    def _calibrate(self, s: SensorSample, t_s: float) -> None:
        for i in range(3):
            self._cal_sum[i] += s.gyro_b[i]
            self._cal_sum[3 + i] += s.acc_b[i]
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
            self.texts.append((Severity.INFO, "Calibrating barometer"))

    def _run_mode(
        self, dt_s: float, acc_up: float, tilt_cos: float
    ) -> tuple[float, float, float, float]:
        st = self.state
        t_roll = self._angle(0)
        t_pitch = self._angle(1)
        yaw_rate = self._yaw_rate()
        if st.hold_for_gcs:
            t_roll = t_pitch = yaw_rate = 0.0
        if st.mode is FlightMode.STABILIZE:
            stick = self._throttle_stick()
            if self.profile is Profile.APM25:
                thr = throttle_apm25(
                    stick, self._thr_hover_param, self._thr_min_param
                )
            else:
                thr = throttle_copter4(stick, self.alt_ctrl.hover_throttle)
            if not st.armed:
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
            return thr, t_roll, t_pitch, yaw_rate
        if st.mode is FlightMode.ALT_HOLD:
            climb = 0.0 if st.hold_for_gcs else self._pilot_climb_cms()
            if not st.armed or (self.land.landed and climb <= 0.0):
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
                return 0.0, t_roll, t_pitch, yaw_rate
            if self.land.landed and self._last_throttle <= 0.0:
                self.alt_ctrl.init_takeoff(self.inav.alt_m * 100.0)
        else:  # LAND
            climb = -self.gains.land_speed_cms
            if not st.armed or self.land.landed:
                self.alt_ctrl.reset(self.inav.alt_m * 100.0, 0.0)
                return 0.0, t_roll, t_pitch, yaw_rate
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
        stick_zero = self._throttle_stick() <= 0.0
        # 3.2.1 (LAND_REQUIRE_MIN_THROTTLE_TO_DISARM) waits for the stick or a failsafe
        disarm_ok = self.profile is Profile.COPTER4 or stick_zero or st.gcs_failsafe
        if st.mode is FlightMode.LAND and self.land.landed and disarm_ok:
            self._disarm()
            return
        if touched:
            self._zero_throttle_s = 0.0
        if self.land.landed and stick_zero and st.mode is FlightMode.STABILIZE:
            self._zero_throttle_s += dt_s
            if self._zero_throttle_s >= AUTO_DISARM_S[self.profile]:
                self._disarm()
        else:
            self._zero_throttle_s = 0.0

    def _failsafes(self, t_s: float, battery_v: float) -> None:
        st = self.state
        action = self._fs_gcs
        change = self.gcs.check(
            t_s,
            requires_override=self.profile is Profile.APM25,
            override_active=self.radio.overridden,
        )
        if action is GcsFailsafeAction.DISABLED and change is True:
            self.gcs.active = False
            change = None
        if change is True:
            st.gcs_failsafe = True
            self.radio.clear_overrides()
            self.texts.append((Severity.CRITICAL, "GCS Failsafe"))
            if st.armed:
                if self.land.landed:
                    self._disarm()
                elif action is GcsFailsafeAction.HOLD_THEN_LAND:
                    if st.mode is not FlightMode.LAND:
                        self._enter_mode(FlightMode.ALT_HOLD)
                        st.hold_for_gcs = True
                elif not (
                    action is GcsFailsafeAction.CONTINUE
                    and self.profile is Profile.APM25
                    and st.mode is FlightMode.LAND
                ):
                    self._enter_mode(FlightMode.LAND)
        elif change is False:
            st.gcs_failsafe = False
            st.hold_for_gcs = False
            self.texts.append((Severity.INFO, "GCS Failsafe Cleared"))
        if self._fs_batt_enabled and self.battery.check(t_s, battery_v, self._fs_batt_voltage):
            st.battery_failsafe = True
            self.texts.append((Severity.CRITICAL, f"Battery failsafe: {battery_v:.2f}V"))
            if st.armed:
                if self.land.landed:
                    self._disarm()
                else:
                    self._enter_mode(FlightMode.LAND)

    @property
    def system_status(self) -> SystemStatus:
        """BOOT while calibrating, STANDBY disarmed, ACTIVE armed, CRITICAL in a failsafe."""
        st = self.state
        if not self.calibrated:
            return SystemStatus.BOOT
        if st.gcs_failsafe or st.battery_failsafe:
            return SystemStatus.CRITICAL
        return SystemStatus.ACTIVE if st.armed else SystemStatus.STANDBY
