"""The bundled-SITL launcher: stdout contract parsing and clear errors when the SITL fails."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.errors import RuntimeFault
from gcs.sitl_process import SitlEndpoints, SitlOptions, SitlProcess, parse_line


def test_parse_endpoint_lines_until_ready() -> None:
    eps: dict[int, list[str]] = {}
    mocap: list[str] = []
    lines = [
        "vehicle 1 tcp:127.0.0.1:40001",
        "vehicle 1 serial:/dev/pts/7",
        "vehicle 2 tcp:127.0.0.1:40011",
        "mocap tcp:127.0.0.1:40100",
        "something else",
    ]
    assert not any(parse_line(line, eps, mocap) for line in lines)
    assert parse_line("ready\n", eps, mocap)
    ep = SitlEndpoints({k: tuple(v) for k, v in eps.items()}, mocap[0])
    assert ep.url(1) == "tcp:127.0.0.1:40001"
    assert ep.url(1, serial=True) == "/dev/pts/7"
    assert ep.url(2) == "tcp:127.0.0.1:40011"
    assert ep.mocap == "tcp:127.0.0.1:40100"
    with pytest.raises(RuntimeFault, match="no serial endpoint for vehicle 2"):
        ep.url(2, serial=True)


def test_command_line_carries_the_options(tmp_path: Path) -> None:
    argv = SitlProcess(SitlOptions(profile="copter4", world=tmp_path / "w.toml", serial=True,
                                   speedup=2.0, seed=4)).command()
    assert argv[1:5] == ["-m", "sitl", "--tcp", "0"]
    joined = " ".join(argv)
    for part in ("--profile copter4", "--speedup 2", "--serial", "--seed 4", "w.toml"):
        assert part in joined


def test_sitl_that_dies_gives_one_clear_line(tmp_path: Path) -> None:
    bad = tmp_path / "broken.toml"
    bad.write_text("[room]\nmin = [0, 0]\n")
    proc = SitlProcess(SitlOptions(world=bad), ready_timeout_s=30.0)
    with pytest.raises(RuntimeFault, match=r"exited with code \d+ before it was ready"):
        proc.start()
    assert proc.proc is not None and proc.proc.poll() is not None


@pytest.mark.e2e
def test_real_sitl_starts_reports_endpoints_and_stops() -> None:
    with SitlProcess(SitlOptions(serial=True)) as sitl:
        url = sitl.endpoints.url(1)
        assert url.startswith("tcp:127.0.0.1:")
        assert sitl.endpoints.url(1, serial=True).startswith("/dev/")
        assert sitl.endpoints.mocap is not None
        proc = sitl.proc
        assert proc is not None and proc.poll() is None
    assert proc.poll() is not None
