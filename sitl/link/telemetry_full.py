"""The rest of the real firmware's stream sets: status, position, EKF and housekeeping messages.

These carry what the simulated vehicle knows (its own estimate, battery, motor outputs) and the
firmware's fixed values otherwise, so that REQUEST_DATA_STREAM(ALL) puts the real firmware's
messages and bytes on the link (see `sitl.link.streams`). GPS_RAW_INT tells the fix the
autopilot flies with (its `gps` option): a 3D fix at the world's origin when it has one,
fix type 1 (no fix) at 0° / 0° as an APM without a lock sends it otherwise; a station
judging what RTL would do reads the same GPS the failsafe acts on. There is no compass.
Fields the station has no use for and the SITL does not model (terrain, mission, memory)
hold the constants the firmware reports on the ground.
"""

from __future__ import annotations

import math
from typing import Any

from sitl.autopilot import FlightMode
from sitl.link.codec import messages
from sitl.link.telemetry import GRAVITY_MSS, boot_ms, clamp16, imu_units
from sitl.link.view import VehicleView

GPS_NO_FIX = 1
GPS_FIX_3D = 3
GPS_SATELLITES = 10  # what the real simulators report with a fix
GPS_EPH_CM = 121  # HDOP 1.21, the real simulators' value
# EKF_STATUS_REPORT flags as the real 4.7 reports them (fixtures' althold-steps tlog): without a
# GPS, attitude, horizontal velocity (held at zero), vertical velocity, absolute vertical
# position and constant-position mode (0xa7), no horizontal position; with a fix and home, both
# horizontal positions and their predictions (0x33f); either way 0x40 (height above ground)
# while the rangefinder reads in range.
EKF_FLAGS_NO_GPS = 0x1 | 0x2 | 0x4 | 0x20 | 0x80
EKF_FLAGS_GPS = 0x1 | 0x2 | 0x4 | 0x8 | 0x10 | 0x20 | 0x100 | 0x200
EKF_FLAG_POS_VERT_AGL = 0x40
ESC_RPM_AT_FULL = 12000.0


def ahrs(v: VehicleView) -> Any:
    """AHRS: DCM's state (no drift estimate modelled, full accelerometer weight)."""
    return messages.MAVLink_ahrs_message(0.0, 0.0, 0.0, 1.0, 0.0, 0.002, 0.0)


def ahrs2(v: VehicleView) -> Any:
    """AHRS2: the secondary estimate (here the same attitude and height)."""
    st = v.autopilot.state
    alt = v.origin.alt_amsl_m + st.alt_m
    return messages.MAVLink_ahrs2_message(st.roll_rad, st.pitch_rad, st.yaw_rad, alt, 0, 0)


def global_position_int(v: VehicleView) -> Any:
    """GLOBAL_POSITION_INT: no horizontal fix; alt above sea level, relative_alt above home."""
    st = v.autopilot.state
    hdg = round(math.degrees(st.yaw_rad) % 360.0 * 100.0) % 36000
    return messages.MAVLink_global_position_int_message(
        boot_ms(v),
        0,
        0,
        round((v.origin.alt_amsl_m + st.alt_m) * 1000.0),
        round(st.alt_m * 1000.0),
        0,
        0,
        clamp16(-st.climb_ms * 100.0),
        hdg,
    )


def gps_raw_int(v: VehicleView) -> Any:
    """GPS_RAW_INT: the fix the autopilot's failsafes act on (RTL needs one)."""
    if not v.autopilot.options.gps:
        return messages.MAVLink_gps_raw_int_message(
            int(v.t_s * 1e6), GPS_NO_FIX, 0, 0, 0, 65535, 65535, 0, 65535, 0
        )
    st = v.autopilot.state
    return messages.MAVLink_gps_raw_int_message(
        int(v.t_s * 1e6), GPS_FIX_3D, round(v.origin.lat_deg * 1e7),
        round(v.origin.lon_deg * 1e7), round((v.origin.alt_amsl_m + st.alt_m) * 1000.0),
        GPS_EPH_CM, GPS_EPH_CM, 0, 65535, GPS_SATELLITES,
    )


def hwstatus(v: VehicleView) -> Any:
    """HWSTATUS (3.2.1): board voltage in mV."""
    return messages.MAVLink_hwstatus_message(5000, 0)


def meminfo(v: VehicleView) -> Any:
    """MEMINFO: what the APM 2.5 reports free (bytes)."""
    return messages.MAVLink_meminfo_message(0, 1800, 0)


def mission_current(v: VehicleView) -> Any:
    """MISSION_CURRENT: no mission."""
    return messages.MAVLink_mission_current_message(0)


def nav_controller_output(v: VehicleView) -> Any:
    """NAV_CONTROLLER_OUTPUT: the altitude error the controller is working on."""
    st = v.autopilot.state
    alt_error = st.target_alt_m - st.alt_m if st.mode is not FlightMode.STABILIZE else 0.0
    hdg = round(math.degrees(st.yaw_rad)) % 360
    return messages.MAVLink_nav_controller_output_message(
        math.degrees(st.roll_rad), math.degrees(st.pitch_rad), hdg, hdg, 0, alt_error, 0.0, 0.0
    )


def system_time(v: VehicleView) -> Any:
    """SYSTEM_TIME: no GPS, so no UNIX time."""
    return messages.MAVLink_system_time_message(0, boot_ms(v))


def terrain_report(v: VehicleView) -> Any:
    """TERRAIN_REPORT: no terrain data loaded."""
    return messages.MAVLink_terrain_report_message(0, 0, 0, 0.0, v.autopilot.state.alt_m, 0, 0)


def terrain_request(v: VehicleView) -> Any:
    """TERRAIN_REQUEST: the firmware asks the GCS for terrain it will not get."""
    return messages.MAVLink_terrain_request_message(0, 0, 100, 0xFFFFFFFFFFFFFFFF)


def sensor_offsets(v: VehicleView) -> Any:
    """SENSOR_OFFSETS (3.2.1): raw pressure and temperature, no compass."""
    c = v.cache
    return messages.MAVLink_sensor_offsets_message(
        0, 0, 0, 0.0, int(c.pressure_pa), int(c.temperature_c * 100.0), 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0,
    )


def scaled_imu2(v: VehicleView) -> Any:
    """SCALED_IMU2: the airframe has one IMU; the second instance reports the same sensor."""
    return messages.MAVLink_scaled_imu2_message(
        boot_ms(v), *imu_units(v), 0, 0, 0, clamp16(v.cache.temperature_c * 100.0)
    )


def scaled_imu3(v: VehicleView) -> Any:
    """SCALED_IMU3: no third IMU (the 4.7 SITL's INS_ACC3_ID is 0): zeros."""
    return messages.MAVLink_scaled_imu3_message(boot_ms(v), 0, 0, 0, 0, 0, 0, 0, 0, 0, 0)


def scaled_pressure2(v: VehicleView) -> Any:
    """SCALED_PRESSURE2: the second barometer instance reports the same sensor."""
    c = v.cache
    return messages.MAVLink_scaled_pressure2_message(
        boot_ms(v), c.pressure_pa / 100.0, 0.0, clamp16(c.temperature_c * 100.0), 0
    )


def power_status(v: VehicleView) -> Any:
    """POWER_STATUS: board and servo rail in mV."""
    return messages.MAVLink_power_status_message(5000, 0, 0)


def battery_status(v: VehicleView) -> Any:
    """BATTERY_STATUS: one pack, total voltage in the first cell, the rest unknown."""
    c = v.cache
    cells = [min(65534, int(c.battery_v * 1000.0))] + [65535] * 9
    return messages.MAVLink_battery_status_message(
        0,
        0,
        0,
        32767,
        cells,
        int(c.current_a * 100.0),
        -1,
        -1,
        int(max(0.0, min(100.0, c.remaining_pct))),
    )


def ekf_status_report(v: VehicleView) -> Any:
    """EKF_STATUS_REPORT: attitude and vertical solution; a horizontal position only with a GPS."""
    flags = EKF_FLAGS_GPS if v.autopilot.options.gps else EKF_FLAGS_NO_GPS
    if v.cache.rangefinder.valid:
        flags |= EKF_FLAG_POS_VERT_AGL
    pos_var = 0.05 if v.autopilot.options.gps else 0.0
    return messages.MAVLink_ekf_status_report_message(flags, 0.05, pos_var, 0.05, 0.0, 0.0)


def vibration(v: VehicleView) -> Any:
    """VIBRATION: how far this IMU sample is from rest (m/s²), no clipping."""
    c = v.cache
    st = v.autopilot.state
    g_z = GRAVITY_MSS * math.cos(st.roll_rad) * math.cos(st.pitch_rad)
    return messages.MAVLink_vibration_message(
        int(v.t_s * 1e6), abs(c.acc_b[0]), abs(c.acc_b[1]), abs(c.acc_b[2] + g_z), 0, 0, 0
    )


def esc_telemetry_1_to_4(v: VehicleView) -> Any:
    """ESC_TELEMETRY_1_TO_4: rpm from the motor outputs, in ArduCopter's motor order."""
    st = v.autopilot.state
    c = v.cache
    motors = st.motors.motors if st.armed else (0.0, 0.0, 0.0, 0.0)
    rpm = [int(m * ESC_RPM_AT_FULL) for m in motors]
    volts = [int(c.battery_v * 100.0)] * 4
    amps = [int(c.current_a * 25.0)] * 4
    return messages.MAVLink_esc_telemetry_1_to_4_message(
        [35] * 4, volts, amps, [0] * 4, rpm, [0] * 4
    )


def timesync(v: VehicleView) -> Any:
    """TIMESYNC request (tc1 0) with the vehicle's clock in ns."""
    return messages.MAVLink_timesync_message(0, int(v.t_s * 1e9))


BUILDERS = {
    "AHRS": ahrs,
    "AHRS2": ahrs2,
    "GLOBAL_POSITION_INT": global_position_int,
    "GPS_RAW_INT": gps_raw_int,
    "HWSTATUS": hwstatus,
    "MEMINFO": meminfo,
    "MISSION_CURRENT": mission_current,
    "NAV_CONTROLLER_OUTPUT": nav_controller_output,
    "SYSTEM_TIME": system_time,
    "TERRAIN_REPORT": terrain_report,
    "TERRAIN_REQUEST": terrain_request,
    "SENSOR_OFFSETS": sensor_offsets,
    "SCALED_IMU2": scaled_imu2,
    "SCALED_IMU3": scaled_imu3,
    "SCALED_PRESSURE2": scaled_pressure2,
    "POWER_STATUS": power_status,
    "BATTERY_STATUS": battery_status,
    "EKF_STATUS_REPORT": ekf_status_report,
    "VIBRATION": vibration,
    "ESC_TELEMETRY_1_TO_4": esc_telemetry_1_to_4,
    "TIMESYNC": timesync,
}
