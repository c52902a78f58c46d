"""What the station's live checks cost per tick: `LiveCheck.tick` every 25 ms with an IMU sample
per tick, over a simulated hour, on this machine's CPU (process time, so neighbours do not count).

    python bench/live_check.py [--ticks N]

Prints µs per tick (mean, and of the slowest of 1000-tick blocks); the loop's budget is 25 ms.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/ shadows packages

from firmware_link.records import Imu
from firmware_link.stats import LinkStats
from gcs.station.live_check import LiveCheck
from gcs.station.loop import TickTiming

PERIOD_S = 0.025


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--ticks", type=int, default=144_000, help="ticks (default: an hour)")
    args = p.parse_args()
    rng = np.random.default_rng(1)
    acc = rng.normal(0.0, 0.5, (args.ticks, 3)) + np.array([0.0, 0.0, -9.81])
    imus = [Imu(k * PERIOD_S, 1, (float(a[0]), float(a[1]), float(a[2])), (0.0, 0.0, 0.0),
                "RAW_IMU") for k, a in enumerate(acc)]
    stats = [LinkStats(rx_messages=12 * k, lost_messages=k // 50) for k in range(args.ticks)]
    timings = [TickTiming(k, k * PERIOD_S, k * PERIOD_S, PERIOD_S, 0.0, 0.0, 0.001, False)
               for k in range(args.ticks)]
    check = LiveCheck()
    blocks = []
    c0 = time.process_time()
    for b in range(0, args.ticks, 1000):
        cb = time.process_time()
        for k in range(b, min(b + 1000, args.ticks)):
            check.imu(imus[k])
            check.tick(k * PERIOD_S, True, stats[k], timings[k])
        blocks.append((time.process_time() - cb) / min(1000, args.ticks - b))
    total = time.process_time() - c0
    print(f"live checks: {args.ticks} ticks, {1e6 * total / args.ticks:.1f} us per tick "
          f"(IMU sample + tick), slowest 1000-tick block {1e6 * max(blocks):.1f} us per tick; "
          f"budget 25000 us")
    print(check.summary()[1])


if __name__ == "__main__":
    main()
