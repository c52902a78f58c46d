"""Errors the link raises; the CLI prints them as one line and exits 1."""

from __future__ import annotations


class LinkError(Exception):
    """The link could not be opened, or the vehicle refused or did not answer a command."""
