"""The recorder's MCAP writer writes the files mcap's own `Writer` writes, byte for byte."""

from __future__ import annotations

import io
import random

import pytest
from mcap.writer import CompressionType, Writer

from logs.mcap_sink import LeanWriter


def _write(cls: type[Writer], chunk_size: int, seed: int) -> bytes:
    rng = random.Random(seed)
    out = io.BytesIO()
    w = cls(out, chunk_size=chunk_size, compression=CompressionType.ZSTD)
    w.start(profile="", library="test")
    schema = w.register_schema(name="s", encoding="jsonschema", data=b"{}")
    channels = [w.register_channel(topic=f"/t{k}", message_encoding="json", schema_id=schema)
                for k in range(3)]
    t = 10**18
    for n in range(3000):
        t += rng.randrange(-2000, 10**6)  # now and then out of order, as merged sources are
        w.add_message(channel_id=rng.choice(channels), log_time=t, publish_time=t + 1,
                      data=bytes(rng.randrange(256) for _ in range(rng.randrange(80))),
                      sequence=n)
        if rng.random() < 0.002:
            w.flush()
        if n == 1500:
            w.add_metadata("m", {"k": "v"})
    w.finish()
    return out.getvalue()


@pytest.mark.parametrize(("chunk_size", "seed"), [(512 * 1024, 1), (4096, 2), (300, 3)])
def test_files_are_the_librarys_own(chunk_size: int, seed: int) -> None:
    assert LeanWriter(io.BytesIO())._lean  # the library is the one it was written against
    assert _write(LeanWriter, chunk_size, seed) == _write(Writer, chunk_size, seed)
