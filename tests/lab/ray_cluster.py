"""A real Ray cluster on this machine for a test: `ray start --head` and a second node with
`ray start --address`, each in its own temporary directory and HOME, on free ports, stopped by
killing exactly the processes it started (never `ray stop`, which kills every Ray on the
machine, other tests' included)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

RAY = str(Path(sys.executable).with_name("ray"))


def free_ports(n: int) -> list[int]:
    """`n` distinct ports nothing listens on now (outside Ray's default worker range)."""
    socks: list[socket.socket] = []
    try:
        while len(socks) < n:
            s = socket.socket()
            s.bind(("127.0.0.1", 0))
            if s.getsockname()[1] > 20000:
                socks.append(s)
            else:
                s.close()
        return [int(s.getsockname()[1]) for s in socks]
    finally:
        for s in socks:
            s.close()


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(
            errors="replace")
    except OSError:
        return ""


def _parent(pid: int) -> int:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return -1
    return int(stat.rpartition(")")[2].split()[1])


def processes_of(marker: str) -> set[int]:
    """Processes whose command line names `marker` (the cluster's own directory), and their
    descendants (workers name only themselves)."""
    pids = [int(p) for p in os.listdir("/proc") if p.isdigit()]
    mine = {p for p in pids if marker in _cmdline(p) and p != os.getpid()}
    grew = True
    while grew:
        children = {p for p in pids if _parent(p) in mine} - mine
        grew = bool(children)
        mine |= children
    return mine


def kill_processes_of(marker: str, timeout_s: float = 10.0) -> set[int]:
    """SIGKILL every process of the cluster under `marker`; the ones that were killed."""
    killed: set[int] = set()
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        left = processes_of(marker)
        if not left:
            break
        for pid in left:
            try:
                os.kill(pid, signal.SIGKILL)
                killed.add(pid)
            except ProcessLookupError:
                pass
        threading.Event().wait(0.1)  # the kernel reaps; the loop ends when none is left
    return killed


class RayCluster:
    """A head and `workers` more nodes, one CPU each; Ray 2.60's `ray start --head` turns token
    authentication on when a token exists in the HOME of `env`."""

    def __init__(self, root: Path, env: dict[str, str], workers: int = 1) -> None:
        self.root = root
        self.env = env
        self.port = free_ports(1)[0]
        self.address = f"127.0.0.1:{self.port}"
        self.workers = workers

    def _node_flags(self, name: str) -> list[str]:
        ports = free_ports(7)
        lo = ports[6]
        return ["--temp-dir", str(self.root / name), "--num-cpus", "1",
                "--disable-usage-stats", "--node-manager-port", str(ports[0]),
                "--object-manager-port", str(ports[1]), "--metrics-export-port", str(ports[2]),
                "--dashboard-agent-listen-port", str(ports[3]),
                "--dashboard-agent-grpc-port", str(ports[4]),
                "--runtime-env-agent-port", str(ports[5]),
                "--min-worker-port", str(lo + 1), "--max-worker-port", str(lo + 60)]

    def start(self) -> None:
        """Start every node; RuntimeError with Ray's own words when one does not start."""
        head = [RAY, "start", "--head", "--port", str(self.port), "--node-ip-address",
                "127.0.0.1", "--include-dashboard", "false",
                "--dashboard-port", str(free_ports(1)[0]), *self._node_flags("head")]
        self._run(head, self.env)
        # a node joining an explicit address is not put in token mode by Ray: told so by Ray's
        # own refusal, a user sets RAY_AUTH_MODE=token, as here
        node_env = {**self.env, "RAY_AUTH_MODE": "token"}
        for k in range(self.workers):
            self._run([RAY, "start", "--address", self.address, "--node-ip-address",
                       "127.0.0.1", *self._node_flags(f"node{k + 1}")], node_env)

    def _run(self, argv: list[str], env: dict[str, str]) -> None:
        done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=180,
                              cwd=self.root)
        if done.returncode != 0:
            raise RuntimeError(f"{' '.join(argv[:3])}: exit {done.returncode}: "
                               f"{(done.stderr or done.stdout).strip()[-800:]}")

    def stop(self) -> set[int]:
        """Kill exactly this cluster's processes."""
        return kill_processes_of(str(self.root))
