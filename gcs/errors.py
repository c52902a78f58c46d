"""Errors a user can cause, each mapped to one line and an exit code by the CLI."""

from __future__ import annotations


class QuadgcsError(Exception):
    """Base of expected errors: printed as one line, no traceback."""

    exit_code = 1


class UsageError(QuadgcsError):
    """Bad flag, bad file, bad input: exit 2."""

    exit_code = 2


class RuntimeFault(QuadgcsError):
    """Something failed at run time (port busy, no vehicle, link lost): exit 1."""

    exit_code = 1


class MissionFailed(QuadgcsError):
    """A mission ran but did not meet its goal (not reached, deadlock): exit 3."""

    exit_code = 3


class FlightFailed(QuadgcsError):
    """A flight did not go as commanded (link lost, a mode it did not ask for, a refusal): 3."""

    exit_code = 3
