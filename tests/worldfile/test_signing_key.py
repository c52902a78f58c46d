"""One signing-key loader: the station's `--signing-key` and the SITL program read a key file
alike, and a bad file ends in one line naming the flag and the file."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.errors import UsageError
from gcs.toml_file import read_signing_key
from worldfile import SigningKeyError, key_from_passphrase, load_signing_key


def test_raw_bytes_and_passphrase_give_the_same_key_to_both_sides(tmp_path: Path) -> None:
    raw = tmp_path / "raw.key"
    raw.write_bytes(bytes(range(32)))
    phrase = tmp_path / "phrase.key"
    phrase.write_text("  indoor flight \n", encoding="utf-8")
    assert read_signing_key(raw) == load_signing_key(raw) == bytes(range(32))
    assert read_signing_key(phrase) == key_from_passphrase("indoor flight")
    assert read_signing_key(None) is None


@pytest.mark.parametrize(("content", "problem"), [
    (None, "cannot read"),
    (b"\xff\xfe" * 5, "10 bytes of binary"),
    (b"two\nlines\n", "one-line passphrase"),
    (b"   \n", "one-line passphrase"),
])
def test_a_bad_key_file_is_one_line(tmp_path: Path, content: bytes | None, problem: str) -> None:
    path = tmp_path / "k.key"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(SigningKeyError) as sitl_side:
        load_signing_key(path)
    with pytest.raises(UsageError) as station_side:
        read_signing_key(path)
    assert problem in str(sitl_side.value)
    assert str(station_side.value) == f"--signing-key {path}: {sitl_side.value}"
    assert "\n" not in str(station_side.value)
