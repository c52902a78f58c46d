"""Reading a TOML file a user gave, with every failure as one line naming the file.

The one wording every reader of the project uses: `<label>: no such <noun>`, `<label>: cannot
read <noun> (<reason>)`, `<label>: <noun> is not UTF-8 text`, `<label>: not valid TOML
(<parser's message>)`. The caller picks the exception type (the station's usage error, the
simulator's world error) so that each side keeps its own exit codes.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any


class TomlFileError(ValueError):
    """A TOML file is missing, unreadable or not TOML; the message is one line."""


def read_toml(path: Path, *, label: str | None = None, noun: str = "file",
              error: type[Exception] = TomlFileError) -> dict[str, Any]:
    """The parsed table of `path`; `error("<label>: ...")` when the file is missing,
    unreadable, not UTF-8 or not TOML. `label` defaults to the path; `noun` says what kind
    of file the user gave (e.g. "world file")."""
    name = str(path) if label is None else label
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise error(f"{name}: no such {noun}") from None
    except OSError as exc:
        raise error(f"{name}: cannot read {noun} ({exc.strerror or exc})") from None
    return parse_toml(raw, label=name, noun=noun, error=error)


def parse_toml(raw: bytes, *, label: str, noun: str = "file",
               error: type[Exception] = TomlFileError) -> dict[str, Any]:
    """The parsed table of a file's bytes, failing in the same words as `read_toml`."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise error(f"{label}: {noun} is not UTF-8 text") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{label}: not valid TOML ({exc})") from None
