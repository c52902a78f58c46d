"""The console script has the bundled SITL; the station's own command line does not, and says
so in one line instead of reaching for it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from lab.cli import build_parser

ROOT = Path(__file__).resolve().parents[2]


def test_the_console_script_has_every_subcommand() -> None:
    names = set(build_parser()._subparsers._group_actions[0].choices)  # type: ignore[union-attr]
    assert {"fly", "mission", "campaign", "replay", "sitl"} <= names


def test_the_station_alone_refuses_a_lockstep_flight_in_one_line() -> None:
    done = subprocess.run([sys.executable, "-m", "gcs", "fly", "--lockstep", "--hold", "1"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "quadgcs fly: --lockstep: this program has no simulator of its own; run it as quadgcs "
        "(or python -m lab), which brings the bundled SITL"]
    assert "sitl" not in {m.split(".")[0] for m in _modules_after("gcs", "--help")}


def _modules_after(package: str, *argv: str) -> list[str]:
    """The modules loaded by `python -m package argv` (printed at exit)."""
    code = ("import atexit, sys, runpy\n"
            "atexit.register(lambda: print('\\n'.join(sys.modules), file=sys.stderr))\n"
            f"sys.argv = ['{package}', *{list(argv)!r}]\n"
            f"runpy.run_module('{package}', run_name='__main__')\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120, check=False)
    return done.stderr.split()


def test_python_m_lab_flies_lockstep() -> None:
    done = subprocess.run([sys.executable, "-m", "lab", "fly", "--lockstep", "--hold", "1",
                           "--no-record", "--json"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    assert '"status": "ok"' in done.stdout
