"""Errors the link raises; the CLI prints them as one line and exits with `exit_code`."""

from __future__ import annotations


class LinkError(Exception):
    """The link could not be opened, or the vehicle refused or did not answer a command."""

    exit_code = 1


class LinkUsageError(LinkError):
    """The caller asked for something malformed (bad connection string, bad key file): exit 2."""

    exit_code = 2


class VehicleNotUp(LinkError):
    """Nothing answers at the vehicle's address yet (refused, no device, no heartbeat): a
    vehicle still booting looks like this, so a caller may wait and try again."""
