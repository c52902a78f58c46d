"""Loop timing with the teleop TUI running: does a busy screen stretch the 25 ms tick?

Flies the bundled SITL (40 Hz telemetry) in PC altitude hold for `--seconds`, with the station in
its own process exactly as `quadgcs teleop` runs it, once with the Textual app redrawing in this
process (headless driver: it composes and renders every frame, as in a terminal, while the
setpoint is stepped up and down by key presses) and once with nothing drawing. Prints the
station's own loop statistics for both. Floor (teleop issue): jitter p99 <= 2 ms with the TUI.
"""

from __future__ import annotations

import argparse
import asyncio
import time

from gcs.pilot import intents
from gcs.pilot.view import LoopView
from gcs.station.session import SessionOptions
from gcs.tui.app import make_app
from gcs.tui.process_backend import ProcessBackend


def wait_view(backend: ProcessBackend, cond, timeout_s: float) -> None:  # type: ignore[no-untyped-def]
    """Poll views until `cond(view)`; blocking here is fine, the station runs elsewhere."""
    deadline = time.monotonic() + timeout_s
    while not cond(backend.view()):
        if time.monotonic() > deadline:
            raise SystemExit(f"bench: condition not met in {timeout_s} s: {backend.view()}")
        time.sleep(0.05)


def fly(seconds: float, with_tui: bool) -> tuple[LoopView, LoopView]:
    """Hover for `seconds`; return the loop view before and after."""
    backend = ProcessBackend(SessionOptions(command="bench", record=False, seed=3))
    try:
        backend.send(intents.Arm())
        wait_view(backend, lambda v: v.vehicle.armed, 30.0)
        backend.send(intents.AltHold(True))
        for _ in range(9):
            backend.send(intents.SetpointStep(0.1))
        wait_view(backend, lambda v: (v.altitude.truth_m or 0.0) > 0.8, 30.0)
        before = backend.view().loop
        if with_tui:

            async def run_app() -> None:
                app = make_app(backend)
                async with app.run_test(size=(120, 40)) as pilot:
                    end = time.monotonic() + seconds
                    k = 0
                    while time.monotonic() < end:
                        await pilot.press("plus" if k % 2 else "minus")
                        await pilot.pause(0.25)
                        k += 1

            asyncio.run(run_app())  # closes the backend on unmount: read the loop first
        else:
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                backend.view()  # keep the pipe drained, as the app's redraw timer does
                time.sleep(0.125)
        after = backend.view().loop
    finally:
        backend.close()
    return before, after


def main() -> None:
    """Print the table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seconds", type=float, default=60.0)
    args = ap.parse_args()
    print(f"{'run':10s} {'ticks':>7s} {'jit p99 ms':>10s} {'cpu p99 ms':>10s} {'overruns':>8s}")
    for label, tui in (("no TUI", False), ("with TUI", True)):
        _, s = fly(args.seconds, tui)
        print(f"{label:10s} {s.ticks:7d} {s.jitter_p99_ms or 0.0:10.3f} "
              f"{s.compute_ms or 0.0:10.3f} {s.overruns:8d}", flush=True)


if __name__ == "__main__":
    main()
