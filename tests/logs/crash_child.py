"""A station stand-in for the crash test: records a 40 Hz tick until it is killed.

Prints `seq t_s` for every tick it has put, so the parent knows what was handed to the recorder.
The ticks run on the station's own fixed-rate loop and clock.
"""

from __future__ import annotations

import sys

from gcs.clock import MonotonicClock
from gcs.station.loop import FixedRateLoop
from logs import Recorder


def main(path: str) -> None:
    """Record /tick at 40 Hz forever."""
    rec = Recorder(path, metadata={"purpose": "crash test"}, flush_interval_s=1.0)
    put = 0  # ticks put, in order (the loop's own index skips the deadlines it missed)

    def tick(_k: int, t_s: float, _period_s: float) -> None:
        nonlocal put
        rec.put("/tick", t_s, {"seq": put, "alt_m": 0.01 * put})
        rec.put_raw("rx", t_s, bytes([0xFD, 1, 0, 0, put % 256, 1, 1, 0, 0, 0, 7, 0, 0]))
        print(put, repr(t_s), flush=True)
        put += 1

    FixedRateLoop(MonotonicClock(), 0.025, tick).run()


if __name__ == "__main__":
    main(sys.argv[1])
