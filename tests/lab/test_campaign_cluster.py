"""A campaign on a real two-node Ray cluster started the ordinary way: `ray start --head` (Ray
2.60 turns token authentication on when a token exists on the machine) and a second node with
`ray start --address`, both on this machine, joined through `quadgcs campaign --address`.
The cluster has its own HOME (its token), directories and ports, and is stopped by killing
exactly its own processes."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("ray", reason="the [campaign] extra is not installed "
                    "(pip install -e '.[campaign]'; make test installs it)")
pytest.importorskip("pyarrow", reason="the [campaign] extra is not installed")

from lab.campaign import read_results
from lab.campaign.pool import join_failure, token_source
from tests.lab.ray_cluster import RayCluster, processes_of

ROOT = Path(__file__).resolve().parents[2]
# two nodes of one CPU each flying lockstep runs: both cores
pytestmark = pytest.mark.solo

TINY = """
name = "tiny"
[fly]
hold_s = 2.0
profile = "copter4"
fix_failsafe = true
[axes]
seed = [1, 2]
"""


def _env(home: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("RAY_AUTH", "RAY_ADDRESS"))}
    env.update(HOME=str(home), RAY_USAGE_STATS_ENABLED="0", OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=str(ROOT))
    return env


@pytest.fixture
def cluster() -> Iterator[RayCluster]:
    # short: Ray's socket paths under it must stay within AF_UNIX's 107 bytes
    root = Path(tempfile.mkdtemp(prefix="qgray", dir="/tmp"))
    home = root / "home"
    (home / ".ray").mkdir(parents=True)
    from ray._private.authentication.authentication_token_generator import (
        generate_new_authentication_token,
    )
    # the token a first local ray.init() leaves behind: the head then starts with auth on
    (home / ".ray" / "auth_token").write_text(generate_new_authentication_token())
    env = _env(home)
    c = RayCluster(root, env)
    try:
        try:
            c.start()
        except RuntimeError as exc:
            pytest.fail(f"the Ray cluster did not start here: {exc}")
        yield c
    finally:
        c.stop()
        left = processes_of(str(root))
        shutil.rmtree(root, ignore_errors=True)
        assert not left, "a process of the test's cluster is left"


def _campaign(tmp_path: Path, address: str,
              env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    spec = tmp_path / "tiny.toml"
    spec.write_text(TINY)
    return subprocess.run([sys.executable, "-m", "lab", "campaign", str(spec), "--address",
                           address, "-o", str(tmp_path / "out"), "--no-plots", "-q"],
                          env=env, capture_output=True, text=True, timeout=300, cwd=ROOT)


@pytest.mark.timeout(600)
def test_a_campaign_runs_on_a_token_authenticated_two_node_cluster(
        cluster: RayCluster, tmp_path: Path) -> None:
    # the client as a user runs it: RAY_AUTH_MODE unset, the token in ~/.ray/auth_token
    env = _env(cluster.root / "home")
    done = _campaign(tmp_path, cluster.address, env)
    assert done.returncode == 0, (done.stdout, done.stderr)
    rows = read_results(tmp_path / "out" / "results.parquet")
    assert sorted(r["seed"] for r in rows) == [1, 2]
    assert all(r["status"] == "ok" for r in rows), [r["reason"] for r in rows]
    assert len({r["worker"] for r in rows}) == 2  # both nodes flew

    # without the token the join fails in one line saying what to set (Ray retries ~20 s)
    bare = tmp_path / "bare-home"
    bare.mkdir()
    done = _campaign(tmp_path, cluster.address, _env(bare))
    assert done.returncode == 1, (done.stdout, done.stderr)
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith(f"quadgcs campaign: --address {cluster.address}: cannot join"), last
    assert "RAY_AUTH_MODE=token" in last and "ray get-auth-token" in last, last


def test_where_the_token_is_looked_for_and_what_a_failed_join_says(tmp_path: Path) -> None:
    home = tmp_path / "home"
    assert token_source({}, home) is None
    (home / ".ray").mkdir(parents=True)
    (home / ".ray" / "auth_token").write_text("x")
    assert token_source({}, home) == str(home / ".ray" / "auth_token")
    assert token_source({"RAY_AUTH_TOKEN": "t"}, home) == "RAY_AUTH_TOKEN"
    assert token_source({"RAY_AUTH_TOKEN_PATH": str(tmp_path / "none")}, home) is None
    line = join_failure("h:1", "Failed to connect", False, None)
    assert "\n" not in line and "set RAY_AUTH_MODE=token" in line
    line = join_failure("h:1", "Failed to connect", True, "RAY_AUTH_TOKEN")
    assert "with token authentication (token from RAY_AUTH_TOKEN)" in line
    assert "ray get-auth-token" in line
