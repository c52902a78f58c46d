"""Start the bundled SITL as a separate program and learn its endpoints from its stdout.

The SITL prints one line per endpoint (`vehicle <sysid> tcp:127.0.0.1:<port>`,
`vehicle <sysid> serial:<path>`, `vehicle <sysid> udp:<host>:<port>`,
`mocap tcp:127.0.0.1:<port>`, with `truth=True` also `truth tcp:127.0.0.1:<port>`: its
evaluation-only ground truth) and then `ready`. The station never imports `sitl`: it speaks to it
only over MAVLink, as it would to a real vehicle.
"""

from __future__ import annotations

import contextlib
import os
import re
import selectors
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from gcs.errors import RuntimeFault

_VEHICLE = re.compile(r"^vehicle (\d+) ((?:tcp|udp|serial):\S+)$")
_MOCAP = re.compile(r"^mocap (tcp:\S+)$")
_TRUTH = re.compile(r"^truth (tcp:\S+)$")


@dataclass(frozen=True, slots=True)
class SitlOptions:
    """What to ask the bundled SITL for."""

    profile: str = "apm25"
    world: Path | None = None
    vehicles: int = 1
    speedup: float = 1.0
    serial: bool = False
    seed: int | None = None
    signing_key: Path | None = None
    no_noise: bool = False
    truth: bool = False  # open the ground-truth endpoint (for scoring only)
    extra_args: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class SitlEndpoints:
    """Connection strings the SITL printed, per vehicle system id."""

    vehicles: dict[int, tuple[str, ...]] = field(default_factory=dict)
    mocap: str | None = None
    truth: str | None = None

    def url(self, sysid: int = 1, serial: bool = False) -> str:
        """The vehicle's serial (pty path) or TCP connection string."""
        urls = self.vehicles.get(sysid, ())
        for u in urls:
            if serial and u.startswith("serial:"):
                return u.removeprefix("serial:")
            if not serial and u.startswith("tcp:"):
                return u
        kind = "serial" if serial else "tcp"
        raise RuntimeFault(f"bundled SITL printed no {kind} endpoint for vehicle {sysid}")


def parse_line(line: str, ep: dict[int, list[str]], mocap: list[str],
               truth: list[str] | None = None) -> bool:
    """Absorb one stdout line; True when it was `ready`."""
    line = line.strip()
    if line == "ready":
        return True
    m = _VEHICLE.match(line)
    if m:
        ep.setdefault(int(m.group(1)), []).append(m.group(2))
    elif (m := _MOCAP.match(line)) is not None:
        mocap.append(m.group(1))
    elif truth is not None and (m := _TRUTH.match(line)) is not None:
        truth.append(m.group(1))
    return False


class SitlProcess:
    """The running SITL subprocess; a context manager that always stops it."""

    def __init__(self, options: SitlOptions, ready_timeout_s: float = 20.0) -> None:
        self.options = options
        self.ready_timeout_s = ready_timeout_s
        self.proc: subprocess.Popen[bytes] | None = None
        self.endpoints = SitlEndpoints()
        self._stderr_path: Path | None = None

    def command(self) -> list[str]:
        """The argv that starts the SITL."""
        o = self.options
        argv = [sys.executable, "-m", "sitl", "--tcp", "0", "--profile", o.profile,
                "--vehicles", str(o.vehicles), "--speedup", f"{o.speedup:g}"]
        if o.world is not None:
            argv += ["--world", str(o.world)]
        if o.serial:
            argv.append("--serial")
        if o.seed is not None:
            argv += ["--seed", str(o.seed)]
        if o.signing_key is not None:
            argv += ["--signing-key", str(o.signing_key)]
        if o.no_noise:
            argv.append("--no-noise")
        if o.truth:
            argv += ["--truth-port", "0"]
        return argv + list(o.extra_args)

    def start(self) -> SitlEndpoints:
        """Start it and wait for `ready`; RuntimeFault with its last words if it fails."""
        with tempfile.NamedTemporaryFile(prefix="quadgcs-sitl-", suffix=".log",
                                         delete=False) as err:
            self._stderr_path = Path(err.name)
            try:
                self.proc = subprocess.Popen(self.command(), stdout=subprocess.PIPE, stderr=err,
                                             stdin=subprocess.DEVNULL)
            except OSError as exc:
                raise RuntimeFault(f"cannot start the bundled SITL: {exc}") from None
        assert self.proc.stdout is not None
        eps: dict[int, list[str]] = {}
        mocap: list[str] = []
        truth: list[str] = []
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        fd = self.proc.stdout.fileno()
        os.set_blocking(fd, False)
        buf = b""
        deadline = time.monotonic() + self.ready_timeout_s
        try:
            while True:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise RuntimeFault(f"bundled SITL not ready within {self.ready_timeout_s:g} s"
                                       f"{self._last_words()}")
                if not sel.select(min(remaining, 0.2)):
                    if self.proc.poll() is not None:
                        raise RuntimeFault(f"bundled SITL exited with code {self.proc.returncode}"
                                           f" before it was ready{self._last_words()}")
                    continue
                chunk = os.read(fd, 4096)
                if not chunk:
                    self.proc.wait(timeout=2.0)
                    raise RuntimeFault(f"bundled SITL exited with code {self.proc.returncode}"
                                       f" before it was ready{self._last_words()}")
                buf += chunk
                *lines, buf = buf.split(b"\n")
                for raw in lines:
                    if parse_line(raw.decode(errors="replace"), eps, mocap, truth):
                        self.endpoints = SitlEndpoints(
                            {k: tuple(v) for k, v in eps.items()}, mocap[0] if mocap else None,
                            truth[0] if truth else None)
                        if not self.endpoints.vehicles:
                            raise RuntimeFault("bundled SITL was ready but printed no endpoint")
                        # keep draining stdout so a chatty SITL never blocks on a full pipe
                        threading.Thread(target=self._drain, args=(fd,), daemon=True).start()
                        return self.endpoints
        except BaseException:
            self.stop()
            raise
        finally:
            sel.close()

    @staticmethod
    def _drain(fd: int) -> None:
        os.set_blocking(fd, True)
        with contextlib.suppress(OSError):
            while os.read(fd, 4096):
                pass

    def _last_words(self) -> str:
        if self._stderr_path is None:
            return ""
        try:
            lines = self._stderr_path.read_text(errors="replace").strip().splitlines()
        except OSError:
            return ""
        return f": {lines[-1]}" if lines else ""

    def stop(self, timeout_s: float = 3.0) -> None:
        """Terminate, wait, kill if it must; idempotent."""
        proc = self.proc
        if proc is not None and proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=timeout_s)
        if self._stderr_path is not None:
            with contextlib.suppress(OSError):
                self._stderr_path.unlink()
            self._stderr_path = None

    def __enter__(self) -> SitlProcess:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
