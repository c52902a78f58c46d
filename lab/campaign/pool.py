"""Running a campaign's runs as Ray tasks: an embedded local Ray by default, or a cluster.

`--address HOST:PORT` (or `RAY_ADDRESS`) joins a running cluster without changing the file;
every node needs quadgcs installed as here. An address nobody answers at is one line, found
with a plain TCP connect first (Ray itself retries for minutes).

Token authentication (Ray 2.60): `ray start --head` turns it on when a token exists on the
head's machine (`~/.ray/auth_token`, which any local `ray.init()` creates, `RAY_AUTH_TOKEN` or
`RAY_AUTH_TOKEN_PATH`), and a client then needs `RAY_AUTH_MODE=token` and the same token. Ray
enables it by itself only for a cluster it finds on its own, never for an explicit address: so
with `RAY_AUTH_MODE` unset and a token here, the join is made in token mode, as Ray does for a
local cluster (a cluster without authentication takes such a client all the same). A join that
fails says in one line what to set. The local Ray starts with the
number of CPUs asked (all of this machine's by default), no dashboard, and none of what only
the dashboard and the state API read (metrics export, task events, the timeline): on two
cores their threads cost the runs about 4 % of the CPU.

Each run is one task of one CPU. A task that raised or whose worker died still gives a row
(`failed`, with the reason), so the campaign goes on. Ctrl-C cancels what has not finished and
returns the rows that had.
"""

from __future__ import annotations

import importlib
import logging
import os
import socket
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from gcs.errors import RuntimeFault, UsageError
from lab.campaign.metrics import failed_row
from lab.campaign.run import RunSpec

ADDRESS_ENV = "RAY_ADDRESS"
AUTH_MODE_ENV = "RAY_AUTH_MODE"
TOKEN_ENV = "RAY_AUTH_TOKEN"
TOKEN_PATH_ENV = "RAY_AUTH_TOKEN_PATH"
CONNECT_TIMEOUT_S = 3.0
# Ray's system settings (ray_config_def.h) for the embedded Ray only: a cluster joined keeps
# whatever it was started with
LOCAL_SYSTEM_CONFIG = {"enable_metrics_collection": False, "task_events_report_interval_ms": 0,
                       "enable_timeline": False}


def need(module: str) -> Any:
    """A campaign dependency, or one line saying how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise UsageError(f"quadgcs campaign needs {module}: pip install 'quadgcs[campaign]' "
                         "(make installs it)") from None


def _check_reachable(address: str) -> None:
    """A TCP connect to HOST:PORT, so an unreachable cluster is one line, not minutes."""
    if address == "auto" or "://" in address:
        return
    host, sep, port = address.rpartition(":")
    if not sep or not port.isdigit():
        raise UsageError(f"--address {address}: expected HOST:PORT of a Ray cluster's head "
                         "(or auto, or ray://HOST:PORT)")
    try:
        with socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT_S):
            pass
    except OSError as exc:
        raise RuntimeFault(f"--address {address}: no Ray cluster answers there "
                           f"({exc.strerror or exc})") from None


def token_source(env: Mapping[str, str], home: Path) -> str | None:
    """Where Ray would read its authentication token from here (never the token): the
    variable's name or the file's path; None when there is none."""
    if env.get(TOKEN_ENV):
        return TOKEN_ENV
    if env.get(TOKEN_PATH_ENV):
        path = Path(env[TOKEN_PATH_ENV]).expanduser()
        return f"{TOKEN_PATH_ENV} ({path})" if path.is_file() else None
    default = home / ".ray" / "auth_token"
    return str(default) if default.is_file() else None


def join_failure(address: str, reason: str, token_mode: bool, source: str | None) -> str:
    """The one line for a join that failed, saying what to set."""
    head = f"--address {address}: cannot join the Ray cluster ({reason})"
    if token_mode:
        return (f"{head} with token authentication (token from {source or 'nowhere'}); it needs "
                "the cluster's own token: `ray get-auth-token` on the head prints it, give it "
                f"in {TOKEN_ENV} or {TOKEN_PATH_ENV}")
    return (f"{head}; if the cluster uses token authentication (Ray 2.60's `ray start --head` "
            f"turns it on when a token exists) set {AUTH_MODE_ENV}=token and its token in "
            f"{TOKEN_ENV}, {TOKEN_PATH_ENV} or ~/.ray/auth_token (`ray get-auth-token` on the "
            "head prints it)")


def _enable_token_auth(ray: Any) -> None:
    """Token mode for this process, as Ray sets it for a local cluster it finds."""
    os.environ[AUTH_MODE_ENV] = "token"
    ray._raylet.Config.initialize("")  # Ray's cached settings read the variable again


@contextmanager
def ray_session(address: str | None, num_cpus: int | None) -> Iterator[Any]:
    """Ray, started locally or joined at `address` (else RAY_ADDRESS); shut down after."""
    ray = need("ray")

    address = address or os.environ.get(ADDRESS_ENV) or None
    quiet: dict[str, Any] = {"log_to_driver": False, "logging_level": logging.ERROR}
    mode_before = os.environ.get(AUTH_MODE_ENV)
    if address is not None:
        _check_reachable(address)
        source = token_source(os.environ, Path.home())
        if mode_before is None and source is not None:
            _enable_token_auth(ray)
        token_mode = os.environ.get(AUTH_MODE_ENV, "").lower() == "token"
        try:
            ray.init(address=address, **quiet)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            _restore_auth_mode(ray, mode_before)
            raise RuntimeFault(join_failure(address, first, token_mode, source)) from None
    else:
        ray.init(num_cpus=num_cpus, include_dashboard=False,
                 _system_config=LOCAL_SYSTEM_CONFIG, **quiet)
    try:
        yield ray
    finally:
        ray.shutdown()
        _restore_auth_mode(ray, mode_before)


def _restore_auth_mode(ray: Any, value: str | None) -> None:
    """RAY_AUTH_MODE as it was before the session (and Ray's cached settings with it)."""
    if os.environ.get(AUTH_MODE_ENV) == value:
        return
    if value is None:
        os.environ.pop(AUTH_MODE_ENV, None)
    else:
        os.environ[AUTH_MODE_ENV] = value
    ray._raylet.Config.initialize("")


def run_all(ray: Any, fn: Callable[..., dict[str, Any]], runs: Sequence[RunSpec],
            args: tuple[Any, ...], on_row: Callable[[dict[str, Any]], None]) -> bool:
    """Run `fn(*args[:1], run, *args[1:])` for every run as a task; `on_row` gets each row as
    it finishes. False when interrupted (Ctrl-C), after cancelling the rest."""
    task = ray.remote(num_cpus=1, max_retries=0)(fn)
    pending: dict[Any, RunSpec] = {}
    for run in runs:
        pending[task.remote(args[0], run, *args[1:])] = run
    try:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
            for ref in ready:
                run = pending.pop(ref)
                try:
                    row = ray.get(ref)
                except Exception as exc:  # the worker died or the task raised: still a row
                    row = failed_row(run.run_id, run.values,
                                     f"worker: {type(exc).__name__}: {_first_line(exc)}")
                on_row(row)
    except KeyboardInterrupt:
        for ref in pending:
            ray.cancel(ref, force=True)
        return False
    return True


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[-1] if text else ""
