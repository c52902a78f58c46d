"""Asking the vehicle what it runs: AUTOPILOT_VERSION, a few telling parameters, the banner.

`identify()` runs once as part of `VehicleLink.open()` (and may be called again). It asks, in
one round trip, for AUTOPILOT_VERSION (MAV_CMD_REQUEST_MESSAGE and the older
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES; 4.x answers, 3.2.1 refuses both) and for the parameters
that tell the families apart (`firmware.PROBE_PARAMS`). It stops as soon as the answers decide
the family and the GCS-id parameter's name: an existing name answers at once, a missing one
never does, so waiting out the deadline is only for a vehicle that says nothing.

The version banner is not asked for by default: PARAM_REQUEST_LIST is the only way to make
ArduCopter 3.2.1 send "ArduCopter V3.2.1", and 3.2.1 starves its telemetry streams while the
list runs (≈ 16 s at about 25 parameters a second: its stream loop serves the parameter queue
first), so asking at connect would cost the telemetry a flight's bring-up needs. A 4.x answers
AUTOPILOT_VERSION instead. `identify(ask_banner=True)` asks (never while armed), and a banner
heard anyway (at boot, or during `fetch_params`) is evidence for the next call.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from firmware_link.firmware import (
    GCS_ID_NEW,
    GCS_ID_OLD,
    HOVER_4X,
    PROBE_PARAMS,
    THR_MID_3X,
    FirmwareEvidence,
    FirmwareInfo,
    decide_firmware,
)
from firmware_link.frames import FrameEndpoint
from firmware_link.records import CommandAck, LinkEventKind, ParamValue

MAV_CMD_REQUEST_MESSAGE = 512
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES = 520
AUTOPILOT_VERSION_ID = 148
MAV_RESULT_ACCEPTED = 0
PROBE_RESEND_S = 0.5
BANNER_WAIT_S = 1.0
BANNER_AFTER_LIST_S = 0.25  # after the first listed parameter, the banner is not coming


class Identification:
    """`identify()` and `firmware`; mixed into `VehicleLink` (LinkCore supplies the link)."""

    _ep: FrameEndpoint
    _clock: Callable[[], float]
    _target_system: int
    _target_component: int
    _evidence: FirmwareEvidence
    _firmware: FirmwareInfo
    _armed: bool
    _send: Callable[[Any], bool]
    _command_long: Callable[..., bool]
    _step: Callable[[float], list[Any]]
    _request_read: Callable[[str], bool]
    _event: Callable[[float, LinkEventKind, str], None]

    def identify(self, timeout_s: float = 1.5, *, ask_banner: bool = False) -> FirmwareInfo:
        """Find out the firmware from what the vehicle says; the result is also `firmware`.

        Never fails for want of evidence: with none, the verdict rests on the wire version
        and its `evidence` says so. `ask_banner` requests the version banner when no version
        number came (see the module docstring for its cost); it is not done while armed.
        """
        ev = self._evidence
        start = self._clock()
        deadline = start + timeout_s
        self._command_long(MAV_CMD_REQUEST_MESSAGE, AUTOPILOT_VERSION_ID)
        self._command_long(MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, 1)
        acks: dict[int, int] = {}
        probes = [n for n in PROBE_PARAMS if n not in ev.params_seen]
        for name in probes:
            self._request_read(name)
        resend_at = start + PROBE_RESEND_S
        while True:
            for rec in self._step(deadline):
                if isinstance(rec, CommandAck) and rec.command in (
                    MAV_CMD_REQUEST_MESSAGE,
                    MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES,
                ):
                    acks[rec.command] = rec.result
            refused = len(acks) == 2 and MAV_RESULT_ACCEPTED not in acks.values()
            version_settled = ev.sw_version is not None or refused
            family = ev.params_seen & {THR_MID_3X, HOVER_4X}
            gcs_id = ev.params_seen & {GCS_ID_OLD, GCS_ID_NEW}
            now = self._clock()
            if (version_settled and family and gcs_id) or now >= deadline:
                break
            if now >= resend_at:
                for name in probes:
                    if name not in ev.params_seen:
                        self._request_read(name)
                resend_at = now + PROBE_RESEND_S
        if ev.sw_version is None:
            ev.version_refused = True
        ev.params_missing |= {n for n in probes if n not in ev.params_seen}
        if ask_banner and ev.sw_version is None and not ev.banner and not self._armed:
            self._ask_banner()
        self._firmware = info = decide_firmware(ev)
        self._ep.wire = info.wire
        self._event(
            self._clock(),
            LinkEventKind.DIALECT,
            f"{info.summary} ({'; '.join(info.evidence)})",
        )
        return info

    def _ask_banner(self) -> None:
        ev = self._evidence
        self._send(
            self._ep.encoder.param_request_list_encode(self._target_system, self._target_component)
        )
        deadline = self._clock() + BANNER_WAIT_S
        while not ev.banner and self._clock() < deadline:
            for rec in self._step(deadline):
                if isinstance(rec, ParamValue) and rec.name not in PROBE_PARAMS:
                    deadline = min(deadline, self._clock() + BANNER_AFTER_LIST_S)
