"""What every `quadgcs COMMAND --help` shows besides the flags: their defaults and one example.

Applied once to the whole parser tree after the commands have registered (`apply`), so a command
module only writes its help lines; a flag's default is appended to its help unless the help
already names it (many say "(default 1.0)" in words that read better than argparse's).
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator

EXAMPLES: dict[str, str] = {
    "sitl": "quadgcs sitl --world worlds/table_room.toml --speedup 2",
    "fly": "quadgcs fly --alt 1.5 --hold 20 --foxglove 8765",
    "teleop": "quadgcs teleop --profile copter4 --foxglove 8765",
    "mission": "quadgcs mission run missions/epbha_table.toml --kinematic",
    "mission run": "quadgcs mission run missions/radiation_3src.toml --kinematic --plot map.png",
    "replay": "quadgcs replay flights/2026-11-22T10-31-05Z_vehicle1.mcap --foxglove 8765",
    "logs": "quadgcs logs info flights/2026-11-22T10-31-05Z_vehicle1.mcap",
    "logs info": "quadgcs logs info flights/2026-11-22T10-31-05Z_vehicle1.mcap",
    "logs export": "quadgcs logs export flight.mcap --tlog flight.tlog --csv csv/",
    "logs recover": "quadgcs logs recover flights/crashed.mcap",
    "logs plot": "quadgcs logs plot flight.mcap -o flight.png",
    "logs import-tlog": "quadgcs logs import-tlog flight.tlog -o flight.mcap",
    "logs check": "quadgcs logs check flights/*.mcap --html review.html",
    "bench": "quadgcs bench foxglove_jitter",
    "params": "quadgcs params --connect tcp:127.0.0.1:5760 get THR_MID",
    "params show": "quadgcs params show 'FS_*'",
    "params get": "quadgcs params get FS_GCS_ENABLE",
    "params set": "quadgcs params set FS_GCS_ENABLE 1",
    "params save": "quadgcs params save vehicle.parm",
    "params load": "quadgcs params load vehicle.parm",
    "params diff": "quadgcs params diff vehicle.parm",
    "campaign": "quadgcs campaign campaigns/hold_seeds.toml --csv",
}


def _with_default(help_text: str | None, action: argparse.Action) -> str | None:
    if not help_text or "default" in help_text.lower() or "%(default)" in help_text:
        return help_text
    default = action.default
    if (default is None or default is False or default is argparse.SUPPRESS or default == []
            or not action.option_strings or isinstance(action, argparse._HelpAction)):
        return help_text
    return f"{help_text} (default %(default)s)"


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """argparse's layout, each flag's default appended where its help does not name it."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        return _with_default(action.help, action)


class RawDefaultsHelpFormatter(argparse.RawDescriptionHelpFormatter):
    """The same for parsers whose description is laid out by hand."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        return _with_default(action.help, action)


def subparsers(parser: argparse.ArgumentParser,
               name: str = "") -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """Every parser below `parser`, with its command path ("mission run")."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                path = f"{name} {sub_name}".strip()
                yield path, sub
                yield from subparsers(sub, path)


def apply(parser: argparse.ArgumentParser) -> None:
    """Defaults in every flag's help and an example in every command's epilog."""
    for path, sub in subparsers(parser):
        fmt = sub.formatter_class
        raw = isinstance(fmt, type) and issubclass(fmt, argparse.RawDescriptionHelpFormatter)
        sub.formatter_class = RawDefaultsHelpFormatter if raw else DefaultsHelpFormatter
        example = EXAMPLES.get(path)
        if example is not None and not sub.epilog:
            sub.epilog = f"example: {example}"
