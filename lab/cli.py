"""The `quadgcs` console script: the station's command line (`gcs.cli`) with the bundled SITL in
this process, for lockstep flights (`fly --lockstep`, `mission run --lockstep`), and the
subcommands that need it (`campaign`)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from gcs import cli
from lab.faultsearch.inject import install

LAB_COMMANDS: tuple[str, ...] = ("lab.commands.campaign",)


def build_parser() -> argparse.ArgumentParser:
    """The parser of every subcommand, the lab's included."""
    return cli.build_parser(LAB_COMMANDS)


def main(argv: Sequence[str] | None = None) -> int:
    """Run one subcommand; return its exit code (2 for usage errors)."""
    install()
    return cli.main(argv, extra=LAB_COMMANDS)


if __name__ == "__main__":
    sys.exit(main())
