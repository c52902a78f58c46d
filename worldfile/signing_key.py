"""MAVLink 2 signing key files, read alike by the station and the simulator.

A key file holds either exactly 32 raw bytes (used as the key), or a passphrase (text; one line,
surrounding whitespace stripped) whose SHA-256 digest is the key — MAVProxy's `signing setup
PASSPHRASE` does the same, so both ends can share a memorable phrase.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

KEY_BYTES = 32


class SigningKeyError(ValueError):
    """A signing key file that cannot be used; the message is one line naming the file."""


def key_from_passphrase(passphrase: str) -> bytes:
    """The 32-byte key MAVProxy derives from a passphrase (SHA-256 of its UTF-8 bytes)."""
    return hashlib.sha256(passphrase.encode("utf-8")).digest()


def load_signing_key(path: str | Path) -> bytes:
    """Read a signing key file (raw 32 bytes, or a passphrase); SigningKeyError if unusable."""
    file = Path(path)
    try:
        data = file.read_bytes()
    except OSError as exc:
        raise SigningKeyError(f"signing key {file}: cannot read: {exc.strerror or exc}") from None
    if len(data) == KEY_BYTES:
        return data
    try:
        text = data.decode("utf-8").strip()
    except UnicodeDecodeError:
        raise SigningKeyError(
            f"signing key {file}: {len(data)} bytes of binary; expected 32 raw bytes "
            "or a text passphrase"
        ) from None
    if not text or "\n" in text:
        raise SigningKeyError(f"signing key {file}: expected 32 raw bytes or a one-line passphrase")
    return key_from_passphrase(text)
