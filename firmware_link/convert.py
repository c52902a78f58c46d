"""Decoded MAVLink messages → typed telemetry records in SI units (pure, no I/O).

Scalings, as ArduPilot fills the messages:
- RAW_IMU: acceleration in milli-g (1 LSB = 1 mg = 9.80665e-3 m/s²) and rates in mrad/s
  (1 LSB = 1e-3 rad/s), in the body FRD frame. ArduPilot's `send_raw_imu` writes
  `accel * 1000 / GRAVITY_MSS` and `gyro * 1000`; MAVLink's message definition names the units
  mG and mrad/s. The thesis (eq. 5.1) converts the MPU-6050's own LSB/g counts on its Arduino;
  on this link the autopilot has already scaled them, so the station only undoes milli-units.
  Only the primary IMU (RAW_IMU) is mapped, so a consumer never mixes two IMUs' streams.
- RANGEFINDER.distance is metres; DISTANCE_SENSOR distances are centimetres.
- SCALED_PRESSURE: hPa and centi-°C. SYS_STATUS: mV, cA (-1 unknown), % (-1 unknown).
- GPS_RAW_INT: only the fix type and satellites (the pre-flight's "can RTL navigate").
- SIMSTATE has attitude and lat/lng but no altitude or velocity: its `pos_n` z and `vel_n` are
  NaN. SIM_STATE carries all of them. Positions are metres north/east/down of the first truth
  fix seen for that vehicle (flat earth, fine over a room).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from firmware_link.records import (
    Attitude,
    Barometer,
    Battery,
    CommandAck,
    GpsFix,
    Heartbeat,
    Imu,
    MocapPose,
    ParamValue,
    Proximity,
    ProximityFacing,
    Radiation,
    Rangefinder,
    RcChannels,
    ServoOutput,
    SimTruth,
    StatusText,
    SystemStatus,
    TelemetryRecord,
    Vec3,
    VfrHud,
)

STANDARD_GRAVITY_MPS2 = 9.80665
MILLI = 1e-3
EARTH_RADIUS_M = 6378137.0
MAV_TYPE_GCS = 6
MAV_MODE_FLAG_SAFETY_ARMED = 128
AUTOPILOT_COMPID = 1
RADIATION_NAME = "RAD_CPS"
UINT16_UNKNOWN = 65535


def text_field(value: Any) -> str:
    """A MAVLink char[] field as str, whichever type pymavlink handed out."""
    if isinstance(value, bytes | bytearray):
        return bytes(value).split(b"\x00", 1)[0].decode("utf-8", errors="replace")
    return str(value).split("\x00", 1)[0]


@dataclass(frozen=True, slots=True)
class SonarLimits:
    """Valid range of the down-facing sonar when the message does not say (RANGEFINDER)."""

    min_distance_m: float = 0.02  # HC-SR04, thesis §5.2
    max_distance_m: float = 4.0


@dataclass
class RecordConverter:
    """Turns one decoded message into zero or more records; keeps only the truth origin."""

    autopilot_compid: int = AUTOPILOT_COMPID
    sonar: SonarLimits = field(default_factory=SonarLimits)
    # the link's lost frames so far, stamped on each rangefinder reading (`Rangefinder.link_lost`)
    lost_frames: Callable[[], int] = lambda: 0
    _origin: dict[int, tuple[float, float]] = field(default_factory=dict)
    _origin_alt: dict[int, float] = field(default_factory=dict)

    def convert(self, msg: Any, t_s: float) -> list[TelemetryRecord]:
        """Records carried by `msg` (a pymavlink message), stamped with receive time `t_s`."""
        handler = _HANDLERS.get(msg.get_type())
        if handler is None:
            return []
        record = handler(self, msg, t_s)
        return [] if record is None else [record]

    def _heartbeat(self, msg: Any, t_s: float) -> Heartbeat | None:
        if msg.type == MAV_TYPE_GCS:
            return None
        try:
            status = SystemStatus(msg.system_status)
        except ValueError:
            status = SystemStatus.UNINIT
        return Heartbeat(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            compid=msg.get_srcComponent(),
            mode=int(msg.custom_mode),
            armed=bool(msg.base_mode & MAV_MODE_FLAG_SAFETY_ARMED),
            system_status=status,
            base_mode=int(msg.base_mode),
        )

    def _attitude(self, msg: Any, t_s: float) -> Attitude:
        return Attitude(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            roll_rad=float(msg.roll),
            pitch_rad=float(msg.pitch),
            yaw_rad=float(msg.yaw),
            rollspeed_rps=float(msg.rollspeed),
            pitchspeed_rps=float(msg.pitchspeed),
            yawspeed_rps=float(msg.yawspeed),
        )

    def _raw_imu(self, msg: Any, t_s: float) -> Imu:
        g_per_count = STANDARD_GRAVITY_MPS2 * MILLI
        return Imu(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            acc_b=(msg.xacc * g_per_count, msg.yacc * g_per_count, msg.zacc * g_per_count),
            gyro_b=(msg.xgyro * MILLI, msg.ygyro * MILLI, msg.zgyro * MILLI),
            source="RAW_IMU",
            time_usec=int(msg.time_usec),
        )

    def _rangefinder(self, msg: Any, t_s: float) -> Rangefinder:
        distance_m = float(msg.distance)
        valid = self.sonar.min_distance_m <= distance_m <= self.sonar.max_distance_m
        return Rangefinder(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            distance_m=distance_m,
            valid=valid,
            source="RANGEFINDER",
            link_lost=self.lost_frames(),
        )

    def _distance_sensor(self, msg: Any, t_s: float) -> Rangefinder | Proximity | None:
        distance_m = msg.current_distance / 100.0
        valid = msg.current_distance > 0 and msg.min_distance <= msg.current_distance
        valid = valid and msg.current_distance <= msg.max_distance
        if msg.get_srcComponent() == self.autopilot_compid:
            if msg.orientation != ProximityFacing.DOWN:
                return None
            return Rangefinder(
                t_s=t_s,
                sysid=msg.get_srcSystem(),
                distance_m=distance_m,
                valid=valid,
                source="DISTANCE_SENSOR",
                link_lost=self.lost_frames(),
            )
        try:
            facing = ProximityFacing(msg.orientation)
        except ValueError:
            return None
        return Proximity(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            facing=facing,
            distance_m=distance_m,
            max_distance_m=msg.max_distance / 100.0,
            valid=valid,
        )

    def _named_value_float(self, msg: Any, t_s: float) -> Radiation | None:
        if text_field(msg.name) != RADIATION_NAME:
            return None
        return Radiation(t_s=t_s, sysid=msg.get_srcSystem(), counts_per_s=float(msg.value))

    def _scaled_pressure(self, msg: Any, t_s: float) -> Barometer:
        return Barometer(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            pressure_pa=float(msg.press_abs) * 100.0,
            temperature_c=msg.temperature / 100.0,
        )

    def _vfr_hud(self, msg: Any, t_s: float) -> VfrHud:
        return VfrHud(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            alt_m=float(msg.alt),
            climb_mps=float(msg.climb),
            throttle_pct=float(msg.throttle),
            heading_deg=float(msg.heading),
            groundspeed_mps=float(msg.groundspeed),
        )

    def _sys_status(self, msg: Any, t_s: float) -> Battery:
        current_a = -1.0 if msg.current_battery < 0 else msg.current_battery / 100.0
        return Battery(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            voltage_v=msg.voltage_battery / 1000.0,
            current_a=current_a,
            remaining_pct=int(msg.battery_remaining),
        )

    def _gps_raw_int(self, msg: Any, t_s: float) -> GpsFix:
        return GpsFix(t_s=t_s, sysid=msg.get_srcSystem(), fix_type=int(msg.fix_type),
                      satellites=int(msg.satellites_visible))

    def _rc_channels(self, msg: Any, t_s: float) -> RcChannels:
        channels = tuple(int(getattr(msg, f"chan{i}_raw")) for i in range(1, 9))
        return RcChannels(t_s=t_s, sysid=msg.get_srcSystem(), channels_us=channels)

    def _servo_output(self, msg: Any, t_s: float) -> ServoOutput:
        outputs = tuple(int(getattr(msg, f"servo{i}_raw")) for i in range(1, 9))
        return ServoOutput(t_s=t_s, sysid=msg.get_srcSystem(), outputs_us=outputs)

    def _statustext(self, msg: Any, t_s: float) -> StatusText:
        return StatusText(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            severity=int(msg.severity),
            text=text_field(msg.text),
        )

    def _command_ack(self, msg: Any, t_s: float) -> CommandAck:
        return CommandAck(
            t_s=t_s, sysid=msg.get_srcSystem(), command=int(msg.command), result=int(msg.result)
        )

    def _param_value(self, msg: Any, t_s: float) -> ParamValue:
        return ParamValue(
            t_s=t_s,
            sysid=msg.get_srcSystem(),
            name=text_field(msg.param_id),
            value=float(msg.param_value),
            index=int(msg.param_index),
            count=int(msg.param_count),
        )

    def _mocap(self, msg: Any, t_s: float) -> MocapPose:
        # The mocap system speaks with its own sysid; its compid names the tracked vehicle.
        q = tuple(float(v) for v in msg.q)
        return MocapPose(
            t_s=t_s,
            sysid=msg.get_srcComponent(),
            pos_n=(float(msg.x), float(msg.y), float(msg.z)),
            q_nb=(q[0], q[1], q[2], q[3]),
            time_usec=int(msg.time_usec),
        )

    def _local_ned(self, sysid: int, lat_deg: float, lon_deg: float, alt_m: float) -> Vec3:
        # Horizontal and vertical origins are kept apart: SIMSTATE has no altitude, so the
        # first SIM_STATE sets the vertical one even when a SIMSTATE set the horizontal one.
        lat0, lon0 = self._origin.setdefault(sysid, (lat_deg, lon_deg))
        north = math.radians(lat_deg - lat0) * EARTH_RADIUS_M
        east = math.radians(lon_deg - lon0) * EARTH_RADIUS_M * math.cos(math.radians(lat0))
        if math.isnan(alt_m):
            return (north, east, math.nan)
        alt0 = self._origin_alt.setdefault(sysid, alt_m)
        return (north, east, -(alt_m - alt0))

    def _simstate(self, msg: Any, t_s: float) -> SimTruth:
        sysid = msg.get_srcSystem()
        pos_n = self._local_ned(sysid, msg.lat * 1e-7, msg.lng * 1e-7, math.nan)
        nan = math.nan
        return SimTruth(
            t_s=t_s,
            sysid=sysid,
            pos_n=pos_n,
            vel_n=(nan, nan, nan),
            roll_rad=float(msg.roll),
            pitch_rad=float(msg.pitch),
            yaw_rad=float(msg.yaw),
            source="SIMSTATE",
        )

    def _sim_state(self, msg: Any, t_s: float) -> SimTruth:
        sysid = msg.get_srcSystem()
        lat_deg = msg.lat_int * 1e-7 if msg.lat_int else float(msg.lat)
        lon_deg = msg.lon_int * 1e-7 if msg.lon_int else float(msg.lon)
        pos_n = self._local_ned(sysid, lat_deg, lon_deg, float(msg.alt))
        return SimTruth(
            t_s=t_s,
            sysid=sysid,
            pos_n=pos_n,
            vel_n=(float(msg.vn), float(msg.ve), float(msg.vd)),
            roll_rad=float(msg.roll),
            pitch_rad=float(msg.pitch),
            yaw_rad=float(msg.yaw),
            source="SIM_STATE",
        )


_HANDLERS = {
    "HEARTBEAT": RecordConverter._heartbeat,
    "ATTITUDE": RecordConverter._attitude,
    "RAW_IMU": RecordConverter._raw_imu,
    "RANGEFINDER": RecordConverter._rangefinder,
    "DISTANCE_SENSOR": RecordConverter._distance_sensor,
    "NAMED_VALUE_FLOAT": RecordConverter._named_value_float,
    "SCALED_PRESSURE": RecordConverter._scaled_pressure,
    "VFR_HUD": RecordConverter._vfr_hud,
    "SYS_STATUS": RecordConverter._sys_status,
    "GPS_RAW_INT": RecordConverter._gps_raw_int,
    "RC_CHANNELS": RecordConverter._rc_channels,
    "RC_CHANNELS_RAW": RecordConverter._rc_channels,
    "SERVO_OUTPUT_RAW": RecordConverter._servo_output,
    "STATUSTEXT": RecordConverter._statustext,
    "COMMAND_ACK": RecordConverter._command_ack,
    "PARAM_VALUE": RecordConverter._param_value,
    "ATT_POS_MOCAP": RecordConverter._mocap,
    "SIMSTATE": RecordConverter._simstate,
    "SIM_STATE": RecordConverter._sim_state,
}
