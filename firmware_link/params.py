"""Parameters as first-class operations: read some, set one and confirm it, fetch them all.

Nothing here falls back to a default. A parameter the vehicle does not answer for is a
`ParamError` naming it; a set is confirmed by the value the vehicle reports back, and a vehicle
that stores something else (it clamps or rounds, or refuses the write) is an error too.

ArduPilot answers PARAM_REQUEST_READ and PARAM_SET with PARAM_VALUE and stays silent for a name
it does not know, so a missing parameter shows only as silence: each request is repeated every
half second until its deadline. Requests are kept to a small window in flight, so asking for many
names neither overflows the send queue nor the vehicle's own queue.
"""

from __future__ import annotations

import math
import struct
from collections import deque
from collections.abc import Callable, Iterable
from typing import Any

from firmware_link.errors import LinkError, LinkUsageError
from firmware_link.frames import FrameEndpoint
from firmware_link.records import ParamValue, StatusText

MAV_PARAM_TYPE_REAL32 = 9
PARAM_NAME_MAX = 16
# MAV_PARAM_TYPE of the integer types ArduPilot uses, and their ranges
INT_RANGES: dict[int, tuple[int, int]] = {
    1: (0, 255),  # UINT8
    2: (-128, 127),  # INT8
    3: (0, 65535),  # UINT16
    4: (-32768, 32767),  # INT16
    5: (0, 2**32 - 1),  # UINT32
    6: (-(2**31), 2**31 - 1),  # INT32
}
READS_IN_FLIGHT = 10
# A request and its answer each cross a lossy radio: at 20 % loss both ways a try fails one
# time in three, and the three tries of a 3 s deadline left lockstep flights unable to read
# one of their 20-odd pre-flight parameters (seeds 4, 6, 7 of 8). A clean link answers within
# about 0.1 s, so resending every half second costs nothing there.
RESEND_S = 0.5
FETCH_STALL_S = 5.0  # a whole-list fetch fails after this long with no new parameter


class ParamError(LinkError):
    """A parameter could not be read or set as asked; `names` lists the ones concerned."""

    def __init__(self, message: str, names: Iterable[str] = ()) -> None:
        super().__init__(message)
        self.names = tuple(names)


def check_param_name(name: str) -> bytes:
    """The name as MAVLink carries it; LinkUsageError for a name no parameter can have."""
    if not name or len(name) > PARAM_NAME_MAX or not name.isascii() or not name.isprintable() or (
        " " in name
    ):
        raise LinkUsageError(
            f"parameter name {name!r}: expected 1..{PARAM_NAME_MAX} ASCII characters"
        )
    return name.encode("ascii")


def as_float32(value: float) -> float:
    """`value` as the vehicle holds it in a PARAM_VALUE (float32)."""
    return float(struct.unpack("<f", struct.pack("<f", value))[0])


def same_param_value(a: float, b: float, ptype: int | None) -> bool:
    """Whether two values are the same parameter value at the precision of its type."""
    if ptype in INT_RANGES:
        return round(a) == round(b)
    return as_float32(a) == as_float32(b)


def check_param_value(name: str, value: float, ptype: int | None) -> None:
    """LinkUsageError for a value the parameter's type cannot hold."""
    if not math.isfinite(value):
        raise LinkUsageError(f"parameter {name}: value {value} is not a finite number")
    if ptype in INT_RANGES:
        low, high = INT_RANGES[ptype]
        if value != round(value):
            raise LinkUsageError(f"parameter {name} is an integer; {value} is not a whole number")
        if not low <= value <= high:
            raise LinkUsageError(f"parameter {name}: {value:.0f} outside its range {low}..{high}")
    elif abs(value) > 3.4e38:
        raise LinkUsageError(f"parameter {name}: {value} does not fit a 32-bit float")


def _names_text(names: list[str]) -> str:
    return ("parameter " if len(names) == 1 else "parameters ") + ", ".join(names)


class ParamProtocol:
    """Parameter exchanges; mixed into `VehicleLink` (LinkCore supplies the link)."""

    _ep: FrameEndpoint
    _clock: Callable[[], float]
    _target_system: int
    _target_component: int
    _param_types: dict[str, int]
    _statustexts: deque[StatusText]
    _send: Callable[[Any], bool]
    _step: Callable[[float], list[Any]]

    def param_type(self, name: str) -> int | None:
        """MAV_PARAM_TYPE of `name` as the vehicle last reported it (None if never seen)."""
        return self._param_types.get(name)

    def _request_read(self, name: str) -> bool:
        msg = self._ep.encoder.param_request_read_encode(
            self._target_system, self._target_component, check_param_name(name), -1
        )
        return self._send(msg)

    def read_params(self, names: Iterable[str], timeout_s: float = 3.0) -> dict[str, float]:
        """The vehicle's values of `names`, in that order; ParamError naming every name the
        vehicle did not answer for within `timeout_s` of asking (unknown names stay silent)."""
        wanted = list(dict.fromkeys(names))
        for name in wanted:
            check_param_name(name)
        got: dict[str, float] = {}
        queue = list(reversed(wanted))
        asked: dict[str, tuple[float, float]] = {}  # name -> (first asked, last asked)
        missing: list[str] = []
        while queue or asked:
            now = self._clock()
            while queue and len(asked) < READS_IN_FLIGHT:
                name = queue.pop()
                self._request_read(name)
                asked[name] = (now, now)
            deadline = min(first + timeout_s for first, _ in asked.values())
            for rec in self._step(deadline):
                if isinstance(rec, ParamValue) and rec.name in asked:
                    got[rec.name] = rec.value
                    del asked[rec.name]
            now = self._clock()
            for name, (first, last) in list(asked.items()):
                if now >= first + timeout_s:
                    missing.append(name)
                    del asked[name]
                elif now >= last + RESEND_S:
                    self._request_read(name)
                    asked[name] = (first, now)
        if missing:
            missing.sort(key=wanted.index)
            raise ParamError(
                f"vehicle {self._target_system}: no value for {_names_text(missing)} "
                f"within {timeout_s:.1f} s (unknown name{'s' if len(missing) > 1 else ''}?)",
                missing,
            )
        return {name: got[name] for name in wanted}

    def get_param(self, name: str, timeout_s: float = 3.0) -> float:
        """Read one parameter (ParamError when the vehicle does not answer)."""
        return self.read_params([name], timeout_s)[name]

    def set_param(self, name: str, value: float, timeout_s: float = 3.0) -> float:
        """Set one parameter and confirm it from the value the vehicle reports back.

        The parameter's type comes from the vehicle (it is read first if never seen), so an
        integer parameter is checked for a whole number in range before anything is sent.
        Returns the stored value; ParamError when the vehicle stores a different one (asked
        again once, so a PARAM_VALUE that was already on its way does not count).
        """
        raw = check_param_name(name)
        if not math.isfinite(value):
            raise LinkUsageError(f"parameter {name}: value {value} is not a finite number")
        if name not in self._param_types:
            self.read_params([name], timeout_s)
        ptype = self._param_types.get(name, MAV_PARAM_TYPE_REAL32)
        check_param_value(name, value, ptype)
        start = self._clock()
        deadline = start + timeout_s
        msg = self._ep.encoder.param_set_encode(
            self._target_system, self._target_component, raw, float(value), ptype
        )
        self._send(msg)
        resend_at = start + RESEND_S
        rechecked = False
        while True:
            for rec in self._step(deadline):
                if not (isinstance(rec, ParamValue) and rec.name == name):
                    continue
                if same_param_value(rec.value, value, ptype):
                    return rec.value
                if rechecked:
                    raise ParamError(self._not_stored(name, value, rec.value, start), [name])
                # The first answer may be a PARAM_VALUE sent before the set was handled.
                rechecked = True
                self._request_read(name)
                resend_at = self._clock() + RESEND_S
            now = self._clock()
            if now >= deadline:
                raise ParamError(
                    f"vehicle {self._target_system}: no confirmation of {name} = {value:g} "
                    f"within {timeout_s:.1f} s",
                    [name],
                )
            if now >= resend_at:
                self._send(msg)
                resend_at = now + RESEND_S

    def _not_stored(self, name: str, wanted: float, got: float, since_s: float) -> str:
        texts = [
            s.text for s in self._statustexts if isinstance(s, StatusText) and s.t_s >= since_s
        ]
        texts = [t for t in texts if t]
        why = f": {texts[-1]}" if texts else " (the firmware limits or rounds it)"
        return (
            f"vehicle {self._target_system} stored {name} = {got:g}, not {wanted:g}{why}"
        ).replace("\n", " ")

    def fetch_params(self, timeout_s: float = 120.0) -> dict[str, float]:
        """Every parameter, by name; the ones a lossy link dropped are asked for by index.

        Fails (ParamError) after `timeout_s` in all, or `FETCH_STALL_S` without a new one:
        ArduCopter 3.2.1 sends about 25 a second (412 take 16 s) and starves its telemetry
        streams meanwhile, so this is for the ground; 4.x sends over 1,300 in ≈ 1 s. The
        version banner both send first is kept as firmware evidence for the next `identify()`.
        """
        start = self._clock()
        deadline = start + timeout_s
        enc = self._ep.encoder
        self._send(enc.param_request_list_encode(self._target_system, self._target_component))
        by_index: dict[int, ParamValue] = {}
        count = -1
        last_new = last_ask = start
        while count < 0 or len(by_index) < count:
            for rec in self._step(deadline):
                if isinstance(rec, ParamValue) and 0 <= rec.index < 65535:
                    count = rec.count
                    if rec.index not in by_index:
                        last_new = self._clock()
                    by_index[rec.index] = rec
            now = self._clock()
            if now >= deadline or now - last_new > FETCH_STALL_S:
                have = len(by_index)
                raise ParamError(
                    f"vehicle {self._target_system}: got {have} of "
                    f"{count if count >= 0 else '?'} parameters in {now - start:.1f} s"
                    + ("" if now >= deadline else f" (none new for {FETCH_STALL_S:.0f} s)")
                )
            if now - max(last_new, last_ask) > RESEND_S:
                last_ask = now
                if count < 0:
                    self._send(enc.param_request_list_encode(
                        self._target_system, self._target_component))
                    continue
                for index in [i for i in range(count) if i not in by_index][:READS_IN_FLIGHT]:
                    self._send(enc.param_request_read_encode(
                        self._target_system, self._target_component, b"", index))
        return {p.name: p.value for p in sorted(by_index.values(), key=lambda p: p.index)}
