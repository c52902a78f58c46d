"""`quadgcs bench [NAME ...]`: run the measurement programs in the source tree's `bench/`.

Each program prints its own numbers (speed, accuracy, timing); this command only finds and runs
them with the station's interpreter, one after another, and stops at the first that fails.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from gcs.errors import RuntimeFault, UsageError

BENCH_DIR = Path(__file__).resolve().parents[2] / "bench"


def available() -> list[str]:
    """Names of the bench programs (file stems), sorted."""
    if not BENCH_DIR.is_dir():
        return []
    return sorted(p.stem for p in BENCH_DIR.glob("*.py") if not p.name.startswith("_"))


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `bench` subcommand."""
    p = sub.add_parser("bench", help="run measurement programs from bench/ (prints numbers)",
                       description=__doc__)
    p.add_argument("names", nargs="*", metavar="NAME",
                   help="bench programs to run (default: list them)")
    p.add_argument("--all", action="store_true", help="run every bench program")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """List or run bench programs."""
    names = available()
    if not names:
        raise UsageError(f"no bench programs found in {BENCH_DIR}: they live in the source tree")
    chosen = names if args.all else args.names
    if not chosen:
        print("bench programs: " + ", ".join(names))
        return 0
    unknown = [n for n in chosen if n not in names]
    if unknown:
        raise UsageError(f"unknown bench {unknown[0]!r}; expected one of {', '.join(names)}")
    for name in chosen:
        print(f"== bench/{name}.py", flush=True)
        # -P: the script's own folder must not shadow packages (bench/planners.py vs planners)
        code = subprocess.call([sys.executable, "-P", str(BENCH_DIR / f"{name}.py")])
        if code != 0:
            raise RuntimeFault(f"bench/{name}.py exited with code {code}")
    return 0
