"""Telemetry messages built from a vehicle view, as ArduCopter fills them.

RAW_IMU and SCALED_IMU carry acceleration in milli-g (value = a · 1000 / 9.80665) and rates in
mrad/s, body FRD: this is what ArduPilot's send_raw_imu writes for every IMU including the APM
2.5's MPU-6000/6050 (the chip's own LSB counts never leave the firmware), so a station converts
with a_mss = xacc · 9.80665e-3 and w_rads = xgyro · 1e-3. (The thesis's eq. 5.1 converts the
chip's LSB/g counts on its own Arduino; behind ArduPilot that conversion has already happened.)
Ground truth goes out as SIM_STATE only (attitude quaternion and Euler angles, body acceleration
and rates, lat/lng, altitude, NED velocity), on both profiles, in the slot where the real SITL
builds send SIMSTATE (which has no altitude). See `sitl.link.streams` for its rate. The rest of
the real firmware's stream sets is built in `sitl.link.telemetry_full`.
"""

from __future__ import annotations

import math
from typing import Any

from sitl.autopilot import FlightMode, Key, Profile
from sitl.link.codec import messages
from sitl.link.view import VehicleView

GRAVITY_MSS = 9.80665
EARTH_RADIUS_M = 6378137.0
MAV_TYPE_QUADROTOR = 2
MAV_AUTOPILOT_ARDUPILOTMEGA = 3
BASE_MODE_DISARMED = 81  # CUSTOM_MODE_ENABLED | STABILIZE_ENABLED | MANUAL_INPUT_ENABLED
BASE_MODE_ARMED = 209  # + SAFETY_ARMED
BASE_MODE_BOOT = 89  # what ArduCopter reports while it initialises (measured on 4.7)
MAV_MODE_FLAG_GUIDED_ENABLED = 8  # RTL and SmartRTL in both firmwares (3.2.1 RTL armed: 217)
GUIDED_MODES = frozenset({FlightMode.RTL, FlightMode.SMART_RTL})
MAV_DISTANCE_SENSOR_ULTRASOUND = 1
MAV_SENSOR_ROTATION_PITCH_270 = 25  # facing down

# SYS_STATUS sensor bits: gyro, accel, abs pressure, laser/sonar position, angular rate control,
# attitude stabilisation, z altitude control, motor outputs, rc receiver, battery
_SENSORS = 0x1 | 0x2 | 0x8 | 0x100 | 0x400 | 0x800 | 0x2000 | 0x8000 | 0x10000 | 0x2000000


def boot_ms(v: VehicleView) -> int:
    """Milliseconds since boot, as a uint32 field wraps them."""
    return int(v.t_s * 1000.0) & 0xFFFFFFFF


def clamp16(x: float) -> int:
    """Rounded into an int16 field."""
    return max(-32768, min(32767, round(x)))


def imu_units(v: VehicleView) -> tuple[int, int, int, int, int, int]:
    """The accelerometer in mg and the gyro in mrad/s, as every IMU message carries them."""
    c = v.cache
    k = 1000.0 / GRAVITY_MSS
    acc, gyro = c.acc_b, c.gyro_b
    return (clamp16(acc[0] * k), clamp16(acc[1] * k), clamp16(acc[2] * k),
            clamp16(gyro[0] * 1000.0), clamp16(gyro[1] * 1000.0), clamp16(gyro[2] * 1000.0))


def heartbeat(v: VehicleView) -> Any:
    """HEARTBEAT as ArduCopter sends it at 1 Hz."""
    st = v.autopilot.state
    if st.armed:
        base_mode = BASE_MODE_ARMED
    elif v.autopilot.booting:
        base_mode = BASE_MODE_BOOT
    else:
        base_mode = BASE_MODE_DISARMED
    if st.mode in GUIDED_MODES:
        base_mode |= MAV_MODE_FLAG_GUIDED_ENABLED
    return messages.MAVLink_heartbeat_message(
        MAV_TYPE_QUADROTOR,
        MAV_AUTOPILOT_ARDUPILOTMEGA,
        base_mode,
        int(st.mode),
        int(v.autopilot.system_status),
        3,
    )


def statustext(severity: int, text: str) -> Any:
    """STATUSTEXT (50 characters at most)."""
    return messages.MAVLink_statustext_message(severity, text.encode("ascii", "replace")[:50])


def attitude(v: VehicleView) -> Any:
    """ATTITUDE: the autopilot's estimate."""
    st = v.autopilot.state
    p, q, r = st.gyro_rads
    return messages.MAVLink_attitude_message(
        boot_ms(v), st.roll_rad, st.pitch_rad, st.yaw_rad, p, q, r
    )


def raw_imu(v: VehicleView) -> Any:
    """RAW_IMU in mg and mrad/s (see module docstring)."""
    return messages.MAVLink_raw_imu_message(
        int(v.t_s * 1e6), *imu_units(v), 0, 0, 0, 0, clamp16(v.cache.temperature_c * 100.0)
    )


def scaled_imu(v: VehicleView) -> Any:
    """SCALED_IMU (Copter 4.x), same units as RAW_IMU."""
    return messages.MAVLink_scaled_imu_message(
        boot_ms(v), *imu_units(v), 0, 0, 0, clamp16(v.cache.temperature_c * 100.0)
    )


def scaled_pressure(v: VehicleView) -> Any:
    """SCALED_PRESSURE: hPa and centidegrees."""
    c = v.cache
    return messages.MAVLink_scaled_pressure_message(
        boot_ms(v), c.pressure_pa / 100.0, 0.0, clamp16(c.temperature_c * 100.0), 0
    )


def sys_status(v: VehicleView, drop_rate_comm: int, errors_comm: int) -> Any:
    """SYS_STATUS with the battery and the link's error counters."""
    c = v.cache
    load = 350  # the APM 2.5's main loop is busy; 35 % is a typical report
    return messages.MAVLink_sys_status_message(
        _SENSORS,
        _SENSORS,
        _SENSORS,
        load,
        int(c.battery_v * 1000.0),
        int(c.current_a * 100.0),
        int(max(0.0, min(100.0, c.remaining_pct))),
        min(10000, drop_rate_comm),
        min(65535, errors_comm),
        0,
        0,
        0,
        0,
        0,
        0,
        0,
    )


def vfr_hud(v: VehicleView) -> Any:
    """VFR_HUD: altitude is the autopilot's own estimate (above home here, no GPS)."""
    st = v.autopilot.state
    heading = int(math.degrees(st.yaw_rad)) % 360
    vn, ve, _ = v.cache.truth_vel_n
    return messages.MAVLink_vfr_hud_message(
        0.0, math.hypot(vn, ve), heading, round(st.throttle * 100.0), st.alt_m, st.climb_ms
    )


def rc_channels(v: VehicleView) -> Any:
    """RC_CHANNELS_RAW (3.2.1) or RC_CHANNELS (4.x): what the autopilot sees."""
    ch = v.autopilot.radio.channels()
    if v.profile is Profile.APM25:
        return messages.MAVLink_rc_channels_raw_message(boot_ms(v), 0, *ch, 255)
    return messages.MAVLink_rc_channels_message(boot_ms(v), 8, *ch, *([0] * 10), 255)


def servo_output_raw(v: VehicleView) -> Any:
    """SERVO_OUTPUT_RAW: motors 1..4 in ArduCopter order (right, left, front, back)."""
    st = v.autopilot.state
    pwm = st.motors.pwm_us() if st.armed else (1000, 1000, 1000, 1000)
    return messages.MAVLink_servo_output_raw_message(
        int(v.t_s * 1e6) & 0xFFFFFFFF, 0, *pwm, 0, 0, 0, 0, *([0] * 8)
    )


def rangefinder_cm(v: VehicleView) -> int:
    """The down sonar as the autopilot reports it: whole centimetres (AP_RangeFinder keeps
    distance_cm as an integer), 0 without an echo or outside RNGFND min..max (so 0 on the floor,
    below the minimum, as both real firmwares read on the ground)."""
    d = v.cache.sonar_m
    if d is None:
        return 0
    cm = round(d * 100.0)
    lo = round(v.params.k(Key.RNG_MIN_M) * 100.0)
    hi = round(v.params.k(Key.RNG_MAX_M) * 100.0)
    return cm if lo <= cm <= hi else 0


def rangefinder(v: VehicleView) -> Any:
    """RANGEFINDER: metres as a float32 of whole centimetres / 100 (3.2.1's distance_cm * 0.01)."""
    return messages.MAVLink_rangefinder_message(rangefinder_cm(v) * 0.01, 0.0)


def distance_sensor_down(v: VehicleView) -> Any:
    """DISTANCE_SENSOR for the down sonar (4.x): uint16 centimetres."""
    p = v.params
    return messages.MAVLink_distance_sensor_message(
        boot_ms(v),
        round(p.k(Key.RNG_MIN_M) * 100.0),
        round(p.k(Key.RNG_MAX_M) * 100.0),
        rangefinder_cm(v),
        MAV_DISTANCE_SENSOR_ULTRASOUND,
        0,
        MAV_SENSOR_ROTATION_PITCH_270,
        0,
        0.0,
        0.0,
        [0.0, 0.0, 0.0, 0.0],
        0,
    )


def _latlon(v: VehicleView) -> tuple[float, float, float]:
    n, e, d = v.cache.truth_pos_n
    o = v.origin
    lat = o.lat_deg + math.degrees(n / EARTH_RADIUS_M)
    lon = o.lon_deg + math.degrees(e / (EARTH_RADIUS_M * math.cos(math.radians(o.lat_deg))))
    return lat, lon, o.alt_amsl_m - d


def sim_state(v: VehicleView) -> Any:
    """SIM_STATE: ground truth with altitude and NED velocity."""
    c = v.cache
    lat, lon, alt = _latlon(v)
    r, p, y = c.truth_euler
    vn, ve, vd = c.truth_vel_n
    return messages.MAVLink_sim_state_message(
        *c.truth_q_nb,
        r,
        p,
        y,
        *c.truth_acc_b,
        *c.truth_omega_b,
        lat,
        lon,
        alt,
        0.0,
        0.0,
        vn,
        ve,
        vd,
        int(lat * 1e7),
        int(lon * 1e7),
    )


def mode_name(mode: FlightMode) -> str:
    """Name of a flight mode for messages."""
    return mode.name
