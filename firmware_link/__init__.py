"""The only package that speaks MAVLink to the vehicle (pymavlink, pyserial)."""

from firmware_link.connection import ConnectionSpec, Transport, parse_connection_string
from firmware_link.dialect import dialect_of_frame
from firmware_link.errors import LinkError, LinkUsageError
from firmware_link.mocap_link import MocapLink
from firmware_link.signing import key_from_passphrase, load_signing_key
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

__all__ = [
    "BringUpReport",
    "BringUpStep",
    "ConnectionSpec",
    "DataStream",
    "LinkError",
    "LinkStats",
    "LinkUsageError",
    "MocapLink",
    "StreamPlan",
    "StreamRate",
    "StreamWanted",
    "Transport",
    "VehicleLink",
    "clamp_pwm_us",
    "dialect_of_frame",
    "key_from_passphrase",
    "load_signing_key",
    "parse_connection_string",
    "plan_streams",
    "wanted_streams",
]
