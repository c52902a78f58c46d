"""The station's MAVLink link: decode throughput, poll() cost in a 25 ms loop, bring-up rates.

1. Decode: the real ArduCopter 4.7 tlog's vehicle frames fed through the link's parser and
   record converter (counting, raw tap off): frames/s and records/s.
2. poll() in a 25 ms loop against the bundled SITL after bring-up to 40 Hz, over TCP and over
   the pseudo-terminal at 115200 baud, with an RC override sent every tick: per-call time
   p50/p99/max and records per tick. Target: poll() never blocks (well under 5 ms).
3. Bring-up per firmware and transport: ATTITUDE rate asked/got per step, bytes/s the link
   carried, and whether the measured budget limited the fast streams.

Prints numbers; asserts nothing.

    .venv/bin/python bench/link.py [--loop-s 5] [--skip-sitl]
"""

from __future__ import annotations

import argparse
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from firmware_link import VehicleLink  # noqa: E402
from firmware_link.convert import RecordConverter  # noqa: E402
from firmware_link.frames import FrameEndpoint  # noqa: E402
from firmware_link.records import RcCommand  # noqa: E402
from tests.fixture_paths import FLIGHT_TLOG  # noqa: E402

FIXTURE = FLIGHT_TLOG
TICK_S = 0.025


def bench_decode() -> None:
    """Frames/s and records/s through the link's parser and converter."""
    from pymavlink import mavutil

    conn = mavutil.mavlink_connection(str(FIXTURE), dialect="ardupilotmega")
    frames = []
    while (msg := conn.recv_msg()) is not None:
        if msg.get_srcSystem() == 1:
            frames.append(bytes(msg.get_msgbuf()))
    conn.close()
    blob = b"".join(frames)
    ep = FrameEndpoint(None, source_system=255, source_component=190, clock=time.monotonic)
    conv = RecordConverter()
    start = time.perf_counter()
    records = 0
    for k in range(0, len(blob), 4096):
        now = time.monotonic()
        for msg in ep.feed(blob[k : k + 4096]):
            records += len(conv.convert(msg, now))
    dt = time.perf_counter() - start
    print(
        f"decode: {len(frames)} frames ({len(blob) / 1e6:.1f} MB) in {dt:.2f} s = "
        f"{len(frames) / dt:,.0f} frames/s, {records / dt:,.0f} records/s "
        f"(a 115200-baud link carries ≈ 300 frames/s)"
    )


def start_sitl(profile: str) -> tuple[subprocess.Popen, str, str]:
    """Start the SITL; return the process, its TCP url and its pty path."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "sitl", "--tcp", "0", "--serial", "--profile", profile],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    assert proc.stdout is not None
    fd, buf, found = proc.stdout.fileno(), b"", {}
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and b"ready\n" not in buf:
        if select.select([fd], [], [], 0.2)[0]:
            chunk = os.read(fd, 4096)
            if not chunk:
                break
            buf += chunk
    for line in buf.decode().splitlines():
        words = line.split()
        if len(words) >= 3 and words[:2] == ["vehicle", "1"]:
            kind, _, rest = words[2].partition(":")
            found[kind] = words[2] if kind == "tcp" else rest
    return proc, found["tcp"], found["serial"]


def bench_loop(url: str, label: str, loop_s: float) -> None:
    """poll() cost per call at the 25 ms cadence after bring-up."""
    with VehicleLink.open(url) as link:
        report = link.bring_up(40.0)
        for line in report.summary_lines():
            print(f"  {line}")
        link.poll()
        costs, per_tick = [], []
        next_t = time.monotonic()
        end = next_t + loop_s
        while next_t < end:
            t0 = time.perf_counter()
            records = link.poll()
            costs.append(time.perf_counter() - t0)
            per_tick.append(len(records))
            link.rc_override(RcCommand(throttle_us=1000))
            next_t += TICK_S
            time.sleep(max(0.0, next_t - time.monotonic()))
        ms = np.array(costs) * 1e3
        stats = link.stats
        p50, p99 = np.percentile(ms, 50), np.percentile(ms, 99)
        print(
            f"poll() {label}: p50 {p50:.3f} ms, p99 {p99:.3f} ms, max {ms.max():.3f} ms "
            f"over {len(ms)} ticks; {np.mean(per_tick):.1f} records/tick; "
            f"rx {stats.rx_messages_per_s:.0f} msg/s, lost {stats.lost_messages}, "
            f"bad {stats.bad_frames}"
        )


def main() -> None:
    """Run the link benchmarks."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loop-s", type=float, default=5.0)
    parser.add_argument("--skip-sitl", action="store_true")
    args = parser.parse_args()
    bench_decode()
    if args.skip_sitl:
        return
    for profile in ("apm25", "copter4"):
        proc, tcp, pty = start_sitl(profile)
        try:
            for label, url in (("tcp", tcp), ("pty 115200", pty)):
                print(f"{profile} over {label}:")
                bench_loop(url, f"{profile} {label}", args.loop_s)
        finally:
            proc.send_signal(signal.SIGTERM)
            proc.wait(timeout=10)
            if proc.stdout is not None:
                proc.stdout.close()


if __name__ == "__main__":
    main()
