"""`python -m sitl.fault_proxy_cli`: put a fault injector between a ground station and a vehicle.

Stdout contract (as the SITL's): `proxy tcp:127.0.0.1:<port>` or `proxy serial:<pty>`, then
`ready`. Window starts count from the first station: its TCP connection, or its first byte on
the pseudo-terminal; standing faults (no `@START+DUR`) act from the start. SIGINT/SIGTERM end
it (exit 0) with each direction's counters on stderr. A bad flag ends in one line, exit 2; a
vehicle endpoint that cannot be opened, exit 1.
"""

from __future__ import annotations

import argparse
import re
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import FrameType
from typing import NoReturn

import serial

from sitl.fault_frames import Direction
from sitl.fault_proxy import FaultProxy

_WINDOW = r"(?P<start>\d+(?:\.\d*)?)\+(?P<dur>\d+(?:\.\d*)?)"
_DROP = re.compile(rf"^(?P<dir>up|down|both):{_WINDOW}$")
_VALUE = re.compile(rf"^(?P<dir>up|down|both):(?P<value>[0-9.eE+-]+)(?:@{_WINDOW})?$")
DIRECTIONS = "up (station to vehicle), down (vehicle to station) or both"


@dataclass(frozen=True, slots=True)
class FaultSpec:
    """One fault flag: what, which way, and when (None: standing from the start)."""

    kind: str  # drop, loss, bitflip, delay
    direction: Direction
    value: float
    start_s: float | None = None
    duration_s: float | None = None


class OneLineParser(argparse.ArgumentParser):
    """Bad flags end in one line naming the flag and what it expects (exit 2)."""

    def error(self, message: str) -> NoReturn:
        """Print `fault_proxy: <message>` and exit 2."""
        self.exit(2, f"fault_proxy: {message}\n")


def _window(m: re.Match[str], flag: str, text: str) -> tuple[float, float]:
    start, dur = float(m["start"]), float(m["dur"])
    if not dur > 0.0:
        raise argparse.ArgumentTypeError(f"{flag} {text!r}: the duration must be > 0 s")
    return start, dur


def _drop(text: str) -> FaultSpec:
    m = _DROP.match(text)
    if m is None:
        raise argparse.ArgumentTypeError(
            f"expected DIR:START+DURATION (seconds; DIR {DIRECTIONS}), got {text!r}")
    start, dur = _window(m, "--drop", text)
    return FaultSpec("drop", Direction(m["dir"]), 1.0, start, dur)


def _valued(kind: str, what: str, lo: float, hi: float) -> Callable[[str], FaultSpec]:
    def parse(text: str) -> FaultSpec:
        m = _VALUE.match(text)
        value = None
        if m is not None:
            try:
                value = float(m["value"])
            except ValueError:
                value = None
        if m is None or value is None or not lo <= value <= hi:
            raise argparse.ArgumentTypeError(
                f"expected DIR:{what}[@START+DURATION] with {what} in {lo:g}..{hi:g} "
                f"(DIR {DIRECTIONS}), got {text!r}")
        if m["start"] is None:
            return FaultSpec(kind, Direction(m["dir"]), value)
        start, dur = _window(m, f"--{kind}", text)
        return FaultSpec(kind, Direction(m["dir"]), value, start, dur)

    parse.__name__ = kind  # argparse names the flag's type in its messages
    return parse


def _target(text: str) -> tuple[str, str | tuple[str, int]]:
    if text.startswith("tcp:"):
        host, sep, port = text[4:].rpartition(":")
        if sep and host and port.isdigit() and 0 < int(port) < 65536:
            return "tcp", (host, int(port))
    elif text.startswith("serial:") and len(text) > 7:
        return "serial", text[7:]
    elif text.startswith("/"):
        return "serial", text
    raise argparse.ArgumentTypeError(
        f"expected tcp:HOST:PORT or serial:/dev/PTY (a path alone means serial), got {text!r}")


def _port(text: str) -> int:
    if not text.isdigit() or not 0 <= int(text) <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, got {text!r}")
    return int(text)


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not value > 0.0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """Parser of `python -m sitl.fault_proxy_cli`."""
    p = OneLineParser(prog="python -m sitl.fault_proxy_cli", description=__doc__,
                      formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--target", type=_target, required=True, metavar="URL",
                   help="the vehicle endpoint: tcp:HOST:PORT, or serial:/dev/pts/N (opened "
                        "with pyserial; the proxy offers a new pseudo-terminal)")
    p.add_argument("--listen", type=_port, default=0, metavar="PORT",
                   help="TCP port the station connects to, on 127.0.0.1 (default 0: any free "
                        "port; printed on stdout)")
    p.add_argument("--drop", type=_drop, action="append", default=[], metavar="DIR:S+D",
                   help="drop everything one way for D s, S s after the first station "
                        "connects (DIR up, down or both; repeatable), e.g. down:30+15")
    p.add_argument("--loss", type=_valued("loss", "P", 0.0, 1.0), action="append",
                   default=[], metavar="DIR:P[@S+D]",
                   help="lose each frame with probability P (standing, or only in the "
                        "window S+D), e.g. both:0.3")
    p.add_argument("--bitflip", type=_valued("bitflip", "P", 0.0, 1.0), action="append",
                   default=[], metavar="DIR:P[@S+D]",
                   help="flip one bit in each frame with probability P, so its CRC fails, "
                        "e.g. both:0.05")
    p.add_argument("--delay", type=_valued("delay", "SECONDS", 0.0, 60.0), action="append",
                   default=[], metavar="DIR:SECONDS[@S+D]",
                   help="hold every byte this long before passing it on, e.g. up:0.1")
    p.add_argument("--seed", type=int, default=0, metavar="N",
                   help="seed of the loss and bit-flip draws (default 0; same seed, same run)")
    p.add_argument("--time-scale", type=_positive, default=1.0, metavar="K",
                   help="simulated seconds per wall second: the SITL's --speedup, so times "
                        "above are simulated seconds (default 1)")
    p.add_argument("--baud", type=int, default=115200, metavar="BAUD",
                   help="serial only: the line's baud rate, kept in simulated time "
                        "(default 115200)")
    return p


def _apply(proxy: FaultProxy, spec: FaultSpec) -> None:
    if spec.kind == "drop":
        assert spec.start_s is not None and spec.duration_s is not None
        proxy.drop(spec.direction, spec.duration_s, spec.start_s, from_station=True)
        return
    kw = {"loss": "loss", "bitflip": "bitflip", "delay": "delay_s"}[spec.kind]
    if spec.start_s is None or spec.duration_s is None:
        proxy.set(spec.direction, **{kw: spec.value})
    else:
        rates = {"loss": 0.0, "bitflip": 0.0, "delay_s": 0.0, kw: spec.value}
        proxy.schedule(spec.direction, spec.start_s, spec.duration_s, from_station=True,
                       loss=rates["loss"], bitflip=rates["bitflip"], delay_s=rates["delay_s"])


def run(args: argparse.Namespace) -> int:
    """Start the proxy, print where it listens, serve until a signal."""
    kind, where = args.target
    try:
        if kind == "tcp":
            proxy = FaultProxy(target=where, listen=("127.0.0.1", args.listen), seed=args.seed,
                               time_scale=args.time_scale, baud=args.baud)
        else:
            proxy = FaultProxy(serial_port=where, seed=args.seed,
                               time_scale=args.time_scale, baud=args.baud)
    except (OSError, serial.SerialException) as exc:
        what = f"--listen {args.listen}" if kind == "tcp" else f"--target serial:{where}"
        print(f"fault_proxy: cannot open {what}: {exc}", file=sys.stderr, flush=True)
        return 1
    specs: list[FaultSpec] = [*args.drop, *args.loss, *args.bitflip, *args.delay]
    for spec in specs:
        _apply(proxy, spec)
    done = threading.Event()

    def _on_signal(_sig: int, _frame: FrameType | None) -> None:
        done.set()

    previous = {s: signal.signal(s, _on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    proxy.start()
    try:
        print(f"proxy {'serial:' if kind == 'serial' else ''}{proxy.address}", flush=True)
        print("ready", flush=True)
        announced = False
        while not done.wait(0.2) and proxy.error is None:
            if not announced and proxy.station_arrived_s is not None:
                announced = True
                for spec in specs:
                    if spec.start_s is not None:
                        what = "drop" if spec.kind == "drop" else f"{spec.kind} {spec.value:g}"
                        print(f"fault_proxy: station arrived; {spec.direction.value} {what} "
                              f"from t={spec.start_s:g} s for {spec.duration_s:g} s",
                              file=sys.stderr, flush=True)
    finally:
        proxy.stop()
        for s, handler in previous.items():
            signal.signal(s, handler)
    for d in (Direction.UP, Direction.DOWN):
        print(f"fault_proxy: {d.value}: {proxy.counters(d).line()}", file=sys.stderr,
              flush=True)
    if proxy.error is not None:
        print(f"fault_proxy: relay stopped: {proxy.error}", file=sys.stderr, flush=True)
        return 1
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `python -m sitl.fault_proxy_cli`."""
    return run(build_parser().parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
