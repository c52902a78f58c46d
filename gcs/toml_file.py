"""Reading a TOML file the station is given, with every failure as one line naming it."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from gcs.errors import UsageError


def read_toml(path: Path, *, label: str, noun: str = "file",
              error: type[Exception] = UsageError) -> dict[str, Any]:
    """The parsed table; `error("{label}: ...")` when the file is missing, unreadable or not
    TOML (`noun` says what kind of file the user gave, e.g. "config file")."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise error(f"{label}: no such {noun}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{label}: cannot read {noun} ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{label}: not valid TOML ({exc})") from None
