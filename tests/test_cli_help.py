"""Every flag of every `quadgcs` command has a help line; each command's --help shows the
defaults and one example; `python -m sitl --help` describes every flag too."""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from gcs.cli import build_parser
from gcs.commands import _help
from sitl.cli import build_parser as sitl_parser

COMMANDS = dict(_help.subparsers(build_parser()))


def _documented(action: argparse.Action) -> bool:
    return isinstance(action.help, str) and action.help.strip() != "" and (
        action.help != argparse.SUPPRESS)


@pytest.mark.parametrize("path", sorted(COMMANDS))
def test_every_flag_has_help(path: str) -> None:
    missing = [a.option_strings or [a.dest] for a in COMMANDS[path]._actions
               if not _documented(a)]
    assert missing == [], f"quadgcs {path}: {missing}"


@pytest.mark.parametrize("path", sorted(COMMANDS))
def test_help_shows_defaults_and_an_example(path: str) -> None:
    parser = COMMANDS[path]
    text = parser.format_help()
    assert f"example: quadgcs {path}" in " ".join(text.split()), text
    for action in parser._actions:
        # a repeatable flag's empty list is "none unless given": nothing to show
        if (action.option_strings
                and action.default not in (None, False, argparse.SUPPRESS, [])
                and not isinstance(action, argparse._HelpAction)):
            # the default, as argparse shows it or in the help's own words
            shown = " ".join(parser._get_formatter()._expand_help(action).split())
            assert "default" in shown.lower(), f"quadgcs {path} {action.option_strings}: {shown}"


def test_the_sitl_program_describes_every_flag() -> None:
    missing = [a.option_strings for a in sitl_parser()._actions if not _documented(a)]
    assert missing == []


def test_quadgcs_sitl_help_as_a_user_sees_it() -> None:
    out = subprocess.run([sys.executable, "-m", "gcs", "sitl", "--help"], capture_output=True,
                         text=True, timeout=60).stdout
    flat = " ".join(out.split())
    for flag, words in (("--vehicles N", "how many vehicles"), ("--speedup K", "faster"),
                        ("--seed N", "seed"), ("--profile", "ArduCopter 3.2.1")):
        assert flag in flat and words in flat, flag
    assert "example: quadgcs sitl" in flat


def test_the_top_level_parser_lists_its_commands_with_help() -> None:
    top = build_parser()
    groups = [a for a in top._actions if isinstance(a, argparse._SubParsersAction)]
    assert groups and all(_documented(g) for g in groups)
    for choice in groups[0]._choices_actions:
        assert _documented(choice), choice.dest
