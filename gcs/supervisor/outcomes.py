"""What became of a request the supervisor was given, as a value callers can branch on.

Every outcome comes with the human note the supervisor writes beside it (the same words the
pilot reads in the events), but a caller decides on `kind`, never on the words: a note may be
reworded for the pilot without any script noticing.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class OutcomeKind(enum.Enum):
    """The end of an arm or take-off request."""

    ARMED = "armed"  # asked to arm, and a heartbeat says the vehicle is armed
    ARM_REFUSED = "arm_refused"  # never sent: the pre-flight checks have not passed
    ARM_IGNORED = "arm_ignored"  # not disarmed (already armed, killed, landing, link lost ...)
    ARM_TIMED_OUT = "arm_timed_out"  # sent and re-sent, the vehicle did not arm in time
    ALT_HOLD_REFUSED = "alt_hold_refused"  # not armed, not in STABILIZE, or the vehicle flies
    LIFTED_OFF = "lifted_off"  # the take-off ramp saw the vehicle leave the floor: hold on
    TAKEOFF_FAILED = "takeoff_failed"  # the ramp's top held and the vehicle stayed down


ARM_FAILED = frozenset({OutcomeKind.ARM_REFUSED, OutcomeKind.ARM_TIMED_OUT})
"""Outcomes after which an arm request is over without an armed vehicle. An ignored request is
not one: the vehicle may already be armed (by the pilot's radio, say)."""


@dataclass(frozen=True, slots=True)
class Outcome:
    """One request's end, at the supervisor's time `t_s`, with the note said for it."""

    kind: OutcomeKind
    t_s: float
    note: str
