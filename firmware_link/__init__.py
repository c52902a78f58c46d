"""The only package that speaks MAVLink to the vehicle (pymavlink, pyserial).

    link = VehicleLink.open("/dev/ttyUSB0,115200")   # or tcp:HOST:PORT, udpin:..., udpout:...
    report = link.bring_up(40.0)                      # streams stepped 100 ms → 25 ms, measured
    while flying:                                     # the station's 25 ms loop owns the link
        records = link.poll()                         # typed records in SI units, never blocks
        link.rc_override(RcCommand(throttle_us=...))
    link.close()                                      # releases the overrides first

Opening identifies the firmware from what the vehicle says (`link.firmware`, a FirmwareInfo).
Blocking helpers (`arm`, `set_mode`, `read_params`, `set_param`, `fetch_params`, `identify`,
`bring_up`) are for the loop's thread between ticks; `send_arm`/`send_disarm`/`send_set_mode`
and `rc_override` return at once (sends never block: see `tx_queue`) and the outcome arrives as
CommandAck / Heartbeat records. Link health: `lost` (no frame of any kind for 1.5 s),
`last_rx_s`, `last_heartbeat_s`; `set_gcs_heartbeat(False)` silences the station's heartbeat so
the vehicle's own GCS failsafe can act. Errors are `LinkError` (exit 1; `ParamError` for
parameters) or `LinkUsageError` (exit 2), one line each. `.parm` files: `parm_file`. Other
ground stations watching through this one: `forward.Forwarder`.
"""

from firmware_link.connection import ConnectionSpec, Transport, parse_connection_string
from firmware_link.dialect import dialect_of_frame
from firmware_link.errors import LinkError, LinkUsageError, VehicleNotUp
from firmware_link.firmware import FirmwareInfo
from firmware_link.forward import Forwarder, ForwardPort, ForwardStats
from firmware_link.mocap_link import MocapLink
from firmware_link.params import ParamError
from firmware_link.parm_file import (
    ParmFileError,
    diff_params,
    format_param_value,
    parse_parm,
    read_parm_file,
    render_parm,
    write_parm_file,
)
from firmware_link.stats import LinkStats
from firmware_link.streams import (
    BringUpReport,
    BringUpStep,
    DataStream,
    StreamPlan,
    StreamRate,
    StreamWanted,
    plan_streams,
    wanted_streams,
)
from firmware_link.vehicle_link import VehicleLink, clamp_pwm_us
from firmware_link.wait_up import DEFAULT_CONNECT_TIMEOUT_S, open_when_up

__all__ = [
    "DEFAULT_CONNECT_TIMEOUT_S",
    "BringUpReport",
    "BringUpStep",
    "ConnectionSpec",
    "DataStream",
    "FirmwareInfo",
    "ForwardPort",
    "ForwardStats",
    "Forwarder",
    "LinkError",
    "LinkStats",
    "LinkUsageError",
    "MocapLink",
    "ParamError",
    "ParmFileError",
    "StreamPlan",
    "StreamRate",
    "StreamWanted",
    "Transport",
    "VehicleLink",
    "VehicleNotUp",
    "clamp_pwm_us",
    "dialect_of_frame",
    "diff_params",
    "format_param_value",
    "open_when_up",
    "parse_connection_string",
    "parse_parm",
    "plan_streams",
    "read_parm_file",
    "render_parm",
    "wanted_streams",
    "write_parm_file",
]
