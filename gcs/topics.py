"""MCAP topic names the station writes; `logs/` reads these (its copy is kept equal by a test)."""

from __future__ import annotations

from firmware_link import records as r

HEARTBEAT = "/vehicle/heartbeat"
ATTITUDE = "/vehicle/attitude"
IMU = "/vehicle/imu"
RANGEFINDER = "/vehicle/rangefinder"
PROXIMITY = "/vehicle/proximity"
RADIATION = "/vehicle/radiation"
BAROMETER = "/vehicle/barometer"
VFR_HUD = "/vehicle/vfr_hud"
BATTERY = "/vehicle/battery"
RC_CHANNELS = "/vehicle/rc_channels"
SERVO_OUTPUT = "/vehicle/servo_output"
STATUS_TEXT = "/vehicle/status_text"
MOCAP_POSE = "/vehicle/mocap_pose"
SIM_TRUTH = "/vehicle/sim_truth"
COMMAND_ACK = "/vehicle/command_ack"
PARAM_VALUE = "/vehicle/param_value"
LINK_EVENT = "/link/events"

ESTIMATE = "/gcs/estimate"
ALT_CONTROLLER = "/gcs/alt_controller"
POSITION_CONTROLLER = "/gcs/position_controller"
RC_OVERRIDE = "/gcs/rc_override"
LOOP = "/gcs/loop"
EVENTS = "/gcs/events"
TICK = "/gcs/tick"  # what each tick consumed and decided (for an exact rerun)
SETUP = "/gcs/setup"  # the station's configuration and throttle curve, once at start
INTENT = "/gcs/intent"  # every pilot/script intent, with the tick that applied it
SUPERVISOR = "/gcs/supervisor"  # the supervisor's changes of state and their reasons

RECORD_TOPICS: dict[type, str] = {
    r.Heartbeat: HEARTBEAT,
    r.Attitude: ATTITUDE,
    r.Imu: IMU,
    r.Rangefinder: RANGEFINDER,
    r.Proximity: PROXIMITY,
    r.Radiation: RADIATION,
    r.Barometer: BAROMETER,
    r.VfrHud: VFR_HUD,
    r.Battery: BATTERY,
    r.RcChannels: RC_CHANNELS,
    r.ServoOutput: SERVO_OUTPUT,
    r.StatusText: STATUS_TEXT,
    r.MocapPose: MOCAP_POSE,
    r.SimTruth: SIM_TRUTH,
    r.CommandAck: COMMAND_ACK,
    r.ParamValue: PARAM_VALUE,
    r.LinkEvent: LINK_EVENT,
}
"""Telemetry record type → its topic (one topic per record type)."""


def topic_for(record: object) -> str | None:
    """The topic a telemetry record goes to, or None for an unknown type."""
    return RECORD_TOPICS.get(type(record))
