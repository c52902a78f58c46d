"""MAVLink 2 signing keys: read from a file, as MAVProxy derives them.

A key file holds either exactly 32 raw bytes (used as the key), or a passphrase (text; one line,
surrounding whitespace stripped) whose SHA-256 digest is the key — MAVProxy's `signing setup
PASSPHRASE` does the same, so both ends can share a memorable phrase.
The signing timestamp counts 10 µs units since 2015-01-01 00:00 UTC (MAVLink's epoch).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from firmware_link.errors import LinkUsageError

KEY_BYTES = 32
SIGNING_EPOCH_UNIX_S = 1420070400  # 2015-01-01T00:00:00Z
TIMESTAMP_UNITS_PER_S = 100_000


def key_from_passphrase(passphrase: str) -> bytes:
    """The 32-byte key MAVProxy derives from a passphrase (SHA-256 of its UTF-8 bytes)."""
    return hashlib.sha256(passphrase.encode("utf-8")).digest()


def load_signing_key(path: str | Path) -> bytes:
    """Read a signing key file (raw 32 bytes, or a passphrase); one-line error if unusable."""
    file = Path(path)
    try:
        data = file.read_bytes()
    except OSError as exc:
        raise LinkUsageError(f"signing key {file}: cannot read: {exc.strerror or exc}") from None
    if len(data) == KEY_BYTES:
        return data
    try:
        text = data.decode("utf-8").strip()
    except UnicodeDecodeError:
        raise LinkUsageError(
            f"signing key {file}: {len(data)} bytes of binary; expected 32 raw bytes "
            "or a text passphrase"
        ) from None
    if not text or "\n" in text:
        raise LinkUsageError(f"signing key {file}: expected 32 raw bytes or a one-line passphrase")
    return key_from_passphrase(text)


def signing_timestamp(unix_time_s: float) -> int:
    """MAVLink signing timestamp for a wall-clock time."""
    return int(max(0.0, unix_time_s - SIGNING_EPOCH_UNIX_S) * TIMESTAMP_UNITS_PER_S)
