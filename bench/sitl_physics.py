"""Speed of the simulated vehicle: physics steps/s and real-time factor with all sensors on.

One simulated second = 400 physics steps of 2.5 ms, the IMU and barometer read at 400 Hz and
50 Hz, the sonar and motion capture polled every 25 ms (the station's tick), the six IR
rangers at 10 Hz and the radiation detector at 10 Hz. Prints numbers; asserts nothing.

    .venv/bin/python bench/sitl_physics.py [--seconds 20] [--world worlds/table_room.toml]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from sitl.vehicle_model import SimVehicle
from sitl.world import default_world, load_world

DT_S = 0.0025


def fly(v: SimVehicle, seconds: float, sensors: bool) -> float:
    """Hover-ish open-loop flight with a slow throttle wobble; returns CPU seconds used."""
    hover = v.hover_throttle()
    steps = round(seconds / DT_S)
    start = time.process_time()
    for k in range(steps):
        u = hover + 0.01 * math.sin(k * (2.0 * math.pi / 400.0))
        v.step((u, u, u, u), DT_S)
        if sensors:
            v.imu()
            if k % 8 == 0:
                v.baro()
            if k % 10 == 0:
                v.sonar()
                while v.mocap() is not None:
                    pass
            if k % 40 == 0:
                v.proximity()
                v.radiation(0.1)
    return time.process_time() - start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per run")
    ap.add_argument("--world", default=None, help="world TOML (default: the empty room)")
    args = ap.parse_args()
    world = load_world(args.world) if args.world else default_world()
    start = world.start_positions_n[0]
    for sensors in (False, True):
        v = SimVehicle(
            world,
            start_pos_n=(start[0], start[1], -1.0),
            rng=np.random.default_rng(1),
            start_hovering=True,
        )
        cpu = fly(v, args.seconds, sensors)
        steps = round(args.seconds / DT_S)
        label = "physics + all sensors" if sensors else "physics only        "
        print(
            f"{label}: {steps / cpu:9.0f} steps/s  {cpu / steps * 1e6:6.1f} us/step  "
            f"{cpu / args.seconds * 1e3:6.2f} ms CPU per simulated s  "
            f"real-time factor {args.seconds / cpu:6.1f}x"
        )


if __name__ == "__main__":
    main()
