"""Reading a TOML file the station is given: the project's one reader (`worldfile.read_toml`),
failing as the station's usage error (exit code 2)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from gcs.errors import UsageError
from worldfile import read_toml as _read_toml


def read_toml(path: Path, *, label: str, noun: str = "file") -> dict[str, Any]:
    """The parsed table; UsageError("{label}: ...") when the file is missing, unreadable or
    not TOML (`noun` says what kind of file the user gave, e.g. "config file")."""
    return _read_toml(path, label=label, noun=noun, error=UsageError)
