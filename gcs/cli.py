"""The station's command line: one entry point, one module per subcommand.

`python -m gcs` is the station alone: it flies vehicles and the SITL as a separate program. The
`quadgcs` console script (`lab.cli`) is this plus what needs the bundled SITL in this process
(lockstep flights, campaigns). Each module in `gcs.commands` (and each extra module the caller
names) exposes `register(subparsers)`, which adds its parser and sets
`func` (taking the parsed namespace, returning an exit code). Expected errors derive from
`gcs.errors.QuadgcsError` and end as one line on stderr with their exit code.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence

from firmware_link.errors import LinkError
from gcs.commands import _help
from gcs.errors import QuadgcsError
from gcs.version import package_version

COMMAND_MODULES: tuple[str, ...] = (
    "sitl",
    "fly",
    "teleop",
    "mission",
    "replay",
    "logs",
    "bench",
    "params",
)


def build_parser(extra: Sequence[str] = ()) -> argparse.ArgumentParser:
    """Build the top-level parser with every available subcommand registered, and those of the
    modules named in `extra` (dotted names) after them."""
    parser = argparse.ArgumentParser(
        prog="quadgcs",
        description="Ground-control station for small indoor quadrotors (MAVLink, ArduCopter).",
    )
    parser.add_argument("--version", action="version",
                        version=f"%(prog)s {package_version()}",
                        help="print the installed version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND",
                                help="what to do (quadgcs COMMAND --help for its flags)")
    for module_name in (*(f"gcs.commands.{name}" for name in COMMAND_MODULES), *extra):
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:
                raise
            continue
        module.register(sub)
    _help.apply(parser)
    return parser


def main(argv: Sequence[str] | None = None, extra: Sequence[str] = ()) -> int:
    """Run one subcommand; return its exit code (2 for usage errors)."""
    parser = build_parser(extra)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(args.func(args) or 0)
    except QuadgcsError as exc:
        print(f"quadgcs {args.command}: {exc}", file=sys.stderr)
        return exc.exit_code
    except LinkError as exc:
        print(f"quadgcs {args.command}: {exc}", file=sys.stderr)
        return exc.exit_code
    except BrokenPipeError:
        # the reader (e.g. `| head`) went away: not an error, and nothing more to say
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except KeyboardInterrupt:
        print(f"quadgcs {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
