"""Sticks, arming and modes: the non-blocking sends, and the blocking helpers built on them.

The `send_*` methods and `rc_override` return at once; their outcome arrives as CommandAck and
Heartbeat records. `arm`, `disarm` and `set_mode` poll the link until the heartbeat confirms,
for the loop's thread between ticks.

How the two firmwares refuse (measured on the real firmware, see the fixtures README):
- ArduCopter 3.2.1 answers a refused arm with COMMAND_ACK UNSUPPORTED (3), not FAILED: a
  pre-arm failure with a STATUSTEXT ("PreArm: INS not calibrated" for ≈ 3 s after boot), a
  throttle-high refusal or a second request while arming is in progress with none. Arming
  itself takes ≈ 1.9 s before its ACK, so a request is not repeated while one is unanswered.
- ArduCopter 4.x answers FAILED with "Arm: ..." / "PreArm: ..." texts until its checks pass
  (≈ 23 s after boot).
With `retry`, every refusal is asked again each second until the deadline, and the error names
the firmware's last reason.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from typing import Any

from firmware_link.errors import LinkError, LinkUsageError
from firmware_link.frames import FrameEndpoint
from firmware_link.pwm import clamp_pwm_us
from firmware_link.records import CommandAck, Dialect, FlightMode, RcCommand, StatusText

MAV_MODE_FLAG_CUSTOM_MODE_ENABLED = 1
MAV_CMD_COMPONENT_ARM_DISARM = 400
MAV_CMD_DO_SET_MODE = 176
SET_MODE_MSG_ID = 11  # ArduCopter acknowledges SET_MODE with this "command"
FORCE_ARM_MAGIC = 2989.0
FORCE_DISARM_MAGIC = 21196.0
RC_RELEASE = 0
RC_LEAVE_ALONE = 65535
ARM_RETRY_S = 1.0  # between a refusal and the next request
ARM_UNANSWERED_S = 3.0  # a request with no ACK by then was lost (3.2.1 takes ≈ 1.9 s)
REASON_GRACE_S = 0.3  # a STATUSTEXT reason may trail its COMMAND_ACK


class MavResult:
    """MAV_RESULT values of COMMAND_ACK."""

    ACCEPTED = 0
    TEMPORARILY_REJECTED = 1
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4
    IN_PROGRESS = 5


RESULT_TEXT = {1: "temporarily rejected", 2: "denied", 3: "unsupported", 4: "failed"}


def one_line(text: str) -> str:
    """A vehicle's text fit for a one-line error."""
    return " ".join(text.split())


class ArmingAndModes:
    """RC overrides, arming and modes; mixed into `VehicleLink` (LinkCore supplies the link)."""

    _ep: FrameEndpoint
    _clock: Callable[[], float]
    _last_stick_s: float
    _target_system: int
    _target_component: int
    _statustexts: deque[StatusText]
    _hb_count: int
    _armed: bool
    _mode: int
    _send: Callable[[Any], bool]
    _send_override_msg: Callable[[Any], bool]
    _command_long: Callable[..., bool]
    _step: Callable[[float], list[Any]]
    dialect: Dialect

    # ------------------------------------------------------------------ sticks
    def rc_override(self, cmd: RcCommand) -> bool:
        """Put one RC_CHANNELS_OVERRIDE in the send slot and write it if the link takes it.

        Never blocks: an override the transport has not taken yet is replaced by this one
        (counted in `LinkStats.tx_dropped_overrides`). 8-channel form, channels 5–8 left alone.
        False when there is nowhere to send (the transport is being reopened).
        """
        chans = [
            clamp_pwm_us(cmd.roll_us),
            clamp_pwm_us(cmd.pitch_us),
            clamp_pwm_us(cmd.throttle_us),
            clamp_pwm_us(cmd.yaw_us),
        ] + [RC_LEAVE_ALONE] * 4
        self._last_stick_s = self._clock()
        return self._override(chans)

    def release_overrides(self) -> bool:
        """Hand channels 1–8 back to the radio (0 = release), so the vehicle's failsafe rules."""
        self._last_stick_s = -math.inf
        return self._override([RC_RELEASE] * 8)

    def _override(self, chans: list[int]) -> bool:
        msg = self._ep.encoder.rc_channels_override_encode(
            self._target_system, self._target_component, *chans
        )
        return self._send_override_msg(msg)

    # ------------------------------------------------------------------ non-blocking commands
    def send_arm(self, force: bool = False) -> bool:
        """Ask the vehicle to arm; the answer comes as a CommandAck record."""
        return self._command_long(MAV_CMD_COMPONENT_ARM_DISARM, 1.0, self._force_magic(force, True))

    def send_disarm(self, force: bool = False) -> bool:
        """Ask the vehicle to disarm; the answer comes as a CommandAck record."""
        return self._command_long(
            MAV_CMD_COMPONENT_ARM_DISARM, 0.0, self._force_magic(force, False)
        )

    def _force_magic(self, force: bool, arm: bool) -> float:
        if not force:
            return 0.0
        if self.dialect is Dialect.APM25:
            raise LinkUsageError("force arm/disarm needs ArduCopter 4.x; APM 2.5 has no force")
        return FORCE_ARM_MAGIC if arm else FORCE_DISARM_MAGIC

    def send_set_mode(self, mode: FlightMode | int) -> bool:
        """Send SET_MODE (works on both dialects); the new mode shows in the next Heartbeat."""
        msg = self._ep.encoder.set_mode_encode(
            self._target_system, MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, int(mode)
        )
        return self._send(msg)

    # ------------------------------------------------------------------ blocking helpers
    def _refusal_reason(self, since_s: float, deadline: float) -> str:
        """The firmware's latest reason since `since_s`, waiting briefly for one to arrive."""
        grace = min(deadline, self._clock() + REASON_GRACE_S)
        while True:
            texts = [s for s in self._statustexts if isinstance(s, StatusText) and s.t_s >= since_s]
            if texts or self._clock() >= grace:
                break
            self._step(grace)
        if not texts:
            if self.dialect is Dialect.APM25:
                return (
                    "no reason given (ArduCopter 3.2.1 refuses silently with the throttle "
                    "above minimum or while arming is in progress)"
                )
            return "no reason given"
        preferred = [s for s in texts if s.text.lower().startswith(("arm", "prearm", "disarm"))]
        return one_line((preferred or texts)[-1].text)

    def arm(self, force: bool = False, timeout_s: float = 5.0, *, retry: bool = False) -> None:
        """Arm and wait until the heartbeat says armed; LinkError with the vehicle's reason.

        With `retry`, a refusal (FAILED, or UNSUPPORTED as ArduCopter 3.2.1 answers, e.g. while
        its pre-arm checks still fail after boot) is asked again every second until
        `timeout_s`; the error names the firmware's latest reason.
        """
        self._arm_disarm(True, force, timeout_s, retry)

    def disarm(self, force: bool = False, timeout_s: float = 5.0, *, retry: bool = False) -> None:
        """Disarm and wait until the heartbeat says disarmed (retry: as for `arm`)."""
        self._arm_disarm(False, force, timeout_s, retry)

    def _arm_disarm(self, want: bool, force: bool, timeout_s: float, retry: bool) -> None:
        verb = "arm" if want else "disarm"
        send = self.send_arm if want else self.send_disarm
        start = self._clock()
        deadline = start + timeout_s
        send(force)
        sent_at = start
        next_send_at = start + ARM_UNANSWERED_S  # only if this request stays unanswered
        hb_seen = self._hb_count
        refusals = 0
        refusal = ""
        while True:
            for rec in self._step(deadline):
                if not isinstance(rec, CommandAck) or rec.command != MAV_CMD_COMPONENT_ARM_DISARM:
                    continue
                if rec.result in (MavResult.ACCEPTED, MavResult.IN_PROGRESS):
                    next_send_at = math.inf  # accepted: the heartbeat will tell
                    continue
                if self._hb_count > 0 and self._armed == want:
                    return  # already so: a refusal of a request that was not needed
                refusals += 1
                reason = self._refusal_reason(sent_at, deadline)
                refusal = (
                    f"vehicle {self._target_system} refused to {verb} "
                    f"({RESULT_TEXT.get(rec.result, str(rec.result))}): {reason}"
                )
                if not retry:
                    raise LinkError(refusal)
                next_send_at = self._clock() + ARM_RETRY_S
            if self._hb_count > hb_seen and self._armed == want:
                return
            now = self._clock()
            if now >= deadline:
                if refusal:
                    raise LinkError(
                        f"{refusal} (kept refusing for {timeout_s:.1f} s, {refusals} times)"
                    )
                raise LinkError(
                    f"vehicle {self._target_system} did not {verb} within {timeout_s:.1f} s"
                )
            if now >= next_send_at:
                send(force)
                sent_at, next_send_at = now, now + ARM_UNANSWERED_S

    def set_mode(self, mode: FlightMode | int, timeout_s: float = 3.0) -> None:
        """Change mode and wait until the heartbeat confirms it."""
        start = self._clock()
        deadline = start + timeout_s
        self.send_set_mode(mode)
        resend_at = start + 0.5
        hb_seen = self._hb_count
        name = mode.name if isinstance(mode, FlightMode) else str(int(mode))
        while True:
            for rec in self._step(deadline):
                if (
                    isinstance(rec, CommandAck)
                    and rec.command in (SET_MODE_MSG_ID, MAV_CMD_DO_SET_MODE)
                    and rec.result not in (MavResult.ACCEPTED, MavResult.IN_PROGRESS)
                ):
                    reason = self._refusal_reason(start, deadline)
                    raise LinkError(f"vehicle {self._target_system} refused mode {name}: {reason}")
            if self._hb_count > hb_seen and self._mode == int(mode):
                return
            now = self._clock()
            if now >= deadline:
                raise LinkError(
                    f"vehicle {self._target_system} did not enter mode {name} "
                    f"within {timeout_s:.1f} s (still in mode {self._mode})"
                )
            if now >= resend_at:
                self.send_set_mode(mode)
                resend_at = now + 0.5

