"""A station stand-in for the crash test: records a 40 Hz tick until it is killed.

Prints `seq t_s` for every tick it has put, so the parent knows what was handed to the recorder.
"""

from __future__ import annotations

import sys
import time

from logs import Recorder


def main(path: str) -> None:
    """Record /tick at 40 Hz forever."""
    rec = Recorder(path, metadata={"purpose": "crash test"}, flush_interval_s=1.0)
    seq = 0
    next_t = time.monotonic()
    while True:
        t = time.monotonic()
        rec.put("/tick", t, {"seq": seq, "alt_m": 0.01 * seq})
        rec.put_raw("rx", t, bytes([0xFD, 1, 0, 0, seq % 256, 1, 1, 0, 0, 0, 7, 0, 0]))
        print(seq, repr(t), flush=True)
        seq += 1
        next_t += 0.025
        time.sleep(max(0.0, next_t - time.monotonic()))  # pacing the 25 ms loop, not syncing


if __name__ == "__main__":
    main(sys.argv[1])
