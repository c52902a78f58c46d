"""The console script's contract: help, unknown commands, exit codes."""

from __future__ import annotations

import subprocess
import sys
from importlib.metadata import version

from gcs.cli import build_parser, main


def test_no_command_prints_help_and_exits_2(capsys) -> None:
    assert main([]) == 2
    assert "usage: quadgcs" in capsys.readouterr().err


def test_console_script_runs_as_module() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "gcs", "--help"], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0
    assert "quadgcs" in proc.stdout


def test_parser_builds() -> None:
    assert build_parser().prog == "quadgcs"


def test_bench_lists_programs_and_rejects_unknown(capsys) -> None:
    assert main(["bench"]) == 0
    assert "alt_hold" in capsys.readouterr().out
    assert main(["bench", "no_such_bench"]) == 2
    assert "unknown bench 'no_such_bench'" in capsys.readouterr().err


def test_version_prints_the_installed_version(capsys) -> None:
    try:
        main(["--version"])
    except SystemExit as exc:
        assert exc.code == 0
    else:
        raise AssertionError("--version must exit")
    assert capsys.readouterr().out.strip() == f"quadgcs {version('quadgcs')}"


def test_version_from_the_console_script() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "gcs", "--version"], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0
    assert proc.stdout.strip() == f"quadgcs {version('quadgcs')}"


def test_version_without_installed_metadata(monkeypatch) -> None:
    import gcs.version as gv

    def missing(name: str) -> str:
        raise gv.PackageNotFoundError(name)

    monkeypatch.setattr(gv, "version", missing)
    assert gv.package_version() == "unknown (not installed)"
