"""Send what the supervisor decided: its command messages, the heartbeat switch, the override."""

from __future__ import annotations

from firmware_link.errors import LinkUsageError
from gcs.station.types import LinkLike
from gcs.supervisor import ActionKind, SupervisorOutput


def send_decision(link: LinkLike, out: SupervisorOutput, heartbeats_on: bool) -> bool:
    """Send `out`'s actions, turn the station's heartbeats on or off as it says and send its
    override (none: silence is the decision). The heartbeats' state now."""
    for a in out.actions:
        if a.kind is ActionKind.ARM:
            link.send_arm(False)
        elif a.kind is ActionKind.DISARM:
            link.send_disarm(False)
        elif a.kind is ActionKind.FORCE_DISARM:
            try:
                link.send_disarm(True)
            except LinkUsageError:  # the firmware turned out to have no force
                link.send_disarm(False)
        elif a.kind is ActionKind.SET_MODE:
            link.send_set_mode(a.mode)
        elif a.kind is ActionKind.RELEASE:
            link.release_overrides()
    if out.heartbeat != heartbeats_on:
        heartbeats_on = out.heartbeat
        link.set_gcs_heartbeat(out.heartbeat)
    if out.command is not None:
        link.rc_override(out.command)
    return heartbeats_on
