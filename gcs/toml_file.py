"""Reading the files the station is given (TOML, signing keys) through the project's one reader
of each (`worldfile`), failing as the station's usage error (exit code 2)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from firmware_link.errors import LinkUsageError
from gcs.errors import UsageError
from worldfile import load_signing_key
from worldfile import read_toml as _read_toml


def read_toml(path: Path, *, label: str, noun: str = "file") -> dict[str, Any]:
    """The parsed table; UsageError("{label}: ...") when the file is missing, unreadable or
    not TOML (`noun` says what kind of file the user gave, e.g. "config file")."""
    return _read_toml(path, label=label, noun=noun, error=UsageError)


def read_signing_key(path: Path | None) -> bytes | None:
    """The key of a `--signing-key` file (None without one); UsageError naming the flag and the
    file when it cannot be used."""
    if path is None:
        return None
    try:
        return load_signing_key(path)
    except (LinkUsageError, OSError, ValueError) as exc:
        raise UsageError(f"--signing-key {path}: {exc}") from None
