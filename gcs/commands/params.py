"""`quadgcs params`: show, get, set, save, load and diff a vehicle's parameters.

As pilots know it from MAVProxy and Mission Planner:

    quadgcs params show [PATTERN]      NAME VALUE lines, sorted; PATTERN as in `ATC_RAT_*`
    quadgcs params get NAME
    quadgcs params set NAME VALUE      read back and confirmed; prints NAME old → new
    quadgcs params save FILE           a .parm file (NAME VALUE, sorted)
    quadgcs params load FILE           sets what differs; reports changed / unchanged / failed;
                                       a file with any line the vehicle cannot take (unknown
                                       name, value its type cannot hold) is refused whole
    quadgcs params diff FILE           the parameters whose vehicle value differs from FILE

With no `--connect` the bundled SITL is started (`--profile`, `--world`, `--serial`, `--seed`,
`--signing-key` as for the other commands). A file is read and checked before any vehicle is
contacted, so a bad line costs nothing. Names are matched case-insensitively (ArduPilot's are
upper case).
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as dt
import fnmatch
import math
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

from firmware_link import (
    DEFAULT_CONNECT_TIMEOUT_S,
    LinkUsageError,
    ParamError,
    VehicleLink,
    diff_params,
    format_param_value,
    open_when_up,
    read_parm_file,
    write_parm_file,
)
from firmware_link.params import check_param_name, check_param_value
from gcs.commands._vehicle_args import add_connect_timeout_argument, connect_timeout
from gcs.errors import RuntimeFault, UsageError
from gcs.sitl_process import SitlOptions, SitlProcess
from gcs.toml_file import read_signing_key

# Names that moved between firmware versions: a pilot's habit from one meets the other.
RENAMED = {
    "SYSID_MYGCS": "MAV_GCS_SYSID (ArduCopter 4.7 renamed it)",
    "MAV_GCS_SYSID": "SYSID_MYGCS (its name before ArduCopter 4.7)",
    "THR_MID": "MOT_THST_HOVER (ArduCopter 4.x's hover throttle, 0..1)",
    "MOT_THST_HOVER": "THR_MID (ArduCopter 3.x's mid-stick throttle, 0..1000)",
}


def _add_vehicle_flags(p: argparse.ArgumentParser, *, on_action: bool) -> None:
    """The vehicle flags. Pilots type them before or after the action, so the actions take
    them too, with suppressed defaults that never overwrite the ones given before."""
    def d(value: object) -> object:
        return argparse.SUPPRESS if on_action else value

    p.add_argument("--connect", metavar="URL", default=d(None),
                   help="vehicle link (tcp:HOST:PORT, udpin:..., /dev/ttyUSB0[,baud]); "
                        "default: start the bundled SITL")
    add_connect_timeout_argument(p, d(DEFAULT_CONNECT_TIMEOUT_S))
    p.add_argument("--profile", choices=("apm25", "copter4"), default=d("apm25"),
                   help="firmware profile of the bundled SITL (default apm25)")
    p.add_argument("--world", type=Path, default=d(None), help="world TOML for the bundled SITL")
    p.add_argument("--serial", action="store_true", default=d(False),
                   help="use the bundled SITL's pseudo-terminal serial port (115200 baud)")
    p.add_argument("--seed", type=int, default=d(None), help="seed of the bundled SITL's noise")
    p.add_argument("--signing-key", type=Path, default=d(None),
                   help="MAVLink 2 signing key file (ArduCopter 4.x)")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the `params` subcommand and its actions."""
    p = sub.add_parser("params", help="show, get, set, save, load or diff vehicle parameters",
                       description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_vehicle_flags(p, on_action=False)
    actions = p.add_subparsers(dest="action", metavar="ACTION", help="what to do")
    specs: tuple[tuple[str, str, Callable[[argparse.ArgumentParser], object]], ...] = (
        ("show", "list parameters (NAME VALUE, sorted)", lambda a: a.add_argument(
            "pattern", nargs="?", default="*", help="shell-style pattern, e.g. 'ATC_RAT_*'")),
        ("get", "print one parameter", lambda a: a.add_argument(
            "name", help="parameter name, e.g. FS_GCS_ENABLE")),
        ("set", "set one parameter and confirm it", lambda a: (
            a.add_argument("name", help="parameter name, e.g. FS_GCS_ENABLE"),
            a.add_argument("value", help="new value (a number)"))),
        ("save", "write every parameter to a .parm file", lambda a: a.add_argument(
            "file", type=Path, help=".parm file to write (NAME VALUE per line)")),
        ("load", "set the parameters of a .parm file", lambda a: a.add_argument(
            "file", type=Path, help=".parm file to read (NAME VALUE per line)")),
        ("diff", "compare the vehicle with a .parm file", lambda a: a.add_argument(
            "file", type=Path, help=".parm file to compare with")),
    )
    for name, helptext, add in specs:
        a = actions.add_parser(name, help=helptext)
        add(a)
        _add_vehicle_flags(a, on_action=True)
    p.set_defaults(func=run, action=None)


# ---------------------------------------------------------------------- checks before connecting
def _name(text: str) -> str:
    name = text.strip().upper()
    try:
        check_param_name(name)
    except LinkUsageError as exc:
        raise UsageError(str(exc)) from None
    return name


def _value(name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"set {name}: value {text!r} is not a number") from None
    if not math.isfinite(value):
        raise UsageError(f"set {name}: value {text!r} is not a finite number")
    return value


def _check_writable(path: Path) -> None:
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise UsageError(f"save {path}: is a directory; expected a file name")
    if not parent.is_dir():
        raise UsageError(f"save {path}: no such directory {parent}")


@contextlib.contextmanager
def _vehicle(args: argparse.Namespace) -> Iterator[VehicleLink]:
    key = read_signing_key(args.signing_key)
    if args.world is not None and not args.world.is_file():
        raise UsageError(f"--world {args.world}: no such file")
    with contextlib.ExitStack() as stack:
        if args.connect is None:
            sitl = SitlProcess(SitlOptions(profile=args.profile, world=args.world,
                                           serial=args.serial, seed=args.seed,
                                           signing_key=args.signing_key))
            endpoints = sitl.start()
            stack.callback(sitl.stop)
            url = endpoints.url(1, serial=args.serial)
            link = stack.enter_context(VehicleLink.open(url, signing_key=key))
        else:
            link = stack.enter_context(open_when_up(
                args.connect, timeout_s=connect_timeout(args), signing_key=key,
                on_wait=lambda line: print(line, file=sys.stderr, flush=True)))
        yield link


def _fmt(link: VehicleLink, name: str, value: float) -> str:
    return format_param_value(value, link.param_type(name))


def _unknown(link: VehicleLink, exc: ParamError) -> UsageError:
    """A name the vehicle does not answer for, while it answers otherwise: the name is wrong."""
    name = exc.names[0] if exc.names else "?"
    hint = RENAMED.get(name)
    fw = link.firmware.name
    tip = f"; did you mean {hint}?" if hint else ""
    return UsageError(f"vehicle {link.target_system} ({fw}) has no parameter {name}{tip}")


def _read_one(link: VehicleLink, name: str) -> float:
    try:
        return link.get_param(name)
    except ParamError as exc:
        if link.lost:
            raise RuntimeFault(f"{exc}; the link to vehicle {link.target_system} is lost") from None
        raise _unknown(link, exc) from None


# ---------------------------------------------------------------------- actions
def _is_pattern(text: str) -> bool:
    return any(ch in text for ch in "*?[")


def _show(link: VehicleLink, pattern: str) -> int:
    pat = pattern.upper()
    if not _is_pattern(pat):
        print(f"{pat} {_fmt(link, pat, _read_one(link, pat))}")
        return 0
    params = link.fetch_params()
    names = sorted(n for n in params if fnmatch.fnmatchcase(n, pat))
    if not names:
        raise RuntimeFault(f"no parameter of vehicle {link.target_system} matches {pattern!r} "
                           f"(of {len(params)})")
    for n in names:
        print(f"{n} {_fmt(link, n, params[n])}")
    return 0


def _set(link: VehicleLink, name: str, value: float) -> int:
    old = _read_one(link, name)
    new = link.set_param(name, value)
    print(f"{name} {_fmt(link, name, old)} → {_fmt(link, name, new)}")
    return 0


def _save(link: VehicleLink, path: Path) -> int:
    params = link.fetch_params()
    # The list brought the version banner (3.2.1 gives its version no other way): the
    # header names the firmware exactly.
    fw = link.identify()
    stamp = dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    header = [fw.summary, f"vehicle {link.target_system}, {len(params)} parameters, {stamp}"]
    types = {n: t for n in params if (t := link.param_type(n)) is not None}
    write_parm_file(path, params, types, header)
    print(f"saved {len(params)} parameters of vehicle {link.target_system} "
          f"({fw.name}) to {path}")
    return 0


def _refusals(link: VehicleLink, current: dict[str, float],
              wanted: dict[str, float]) -> list[str]:
    """Every line of the file the vehicle could not take, as `NAME VALUE: why`: a name it does
    not have, a value its parameter's type cannot hold (not a whole number, out of range)."""
    refused: list[str] = []
    for name, value in wanted.items():
        shown = format_param_value(value)
        if name not in current:
            hint = RENAMED.get(name)
            refused.append(f"{name} {shown}: unknown name, not a parameter of this vehicle"
                           + (f" (did you mean {hint}?)" if hint else ""))
            continue
        try:
            check_param_value(name, value, link.param_type(name))
        except LinkUsageError as exc:
            refused.append(f"{name} {shown}: {_why(exc)}")
    return refused


def _why(exc: LinkUsageError) -> str:
    """The reason of a value check, without the parameter name the line already starts with."""
    text = str(exc)
    _, sep, rest = text.partition(": ")
    if sep and text.startswith("parameter "):
        return f"out of range: {rest}" if "outside" in rest else f"wrong type: {rest}"
    if "whole number" in text:
        return "wrong type: the parameter is an integer, the value is not a whole number"
    return text


def _load(link: VehicleLink, path: Path, wanted: dict[str, float]) -> int:
    current = link.fetch_params()
    # All or nothing: a half-applied file leaves the vehicle in a state no file describes.
    refused = _refusals(link, current, wanted)
    if refused:
        for line in refused:
            print(f"quadgcs params: load {path}: refused {line}", file=sys.stderr)
        raise UsageError(f"load {path}: {len(refused)} of {len(wanted)} lines refused; "
                         "nothing was written to the vehicle")
    changed = unchanged = 0
    failed: list[str] = []
    for name, value in wanted.items():
        old = current[name]
        kind = link.param_type(name)
        if format_param_value(old, kind) == format_param_value(value, kind):
            unchanged += 1
            continue
        try:
            new = link.set_param(name, value)
        except (ParamError, LinkUsageError) as exc:
            # the vehicle refused or changed a value its type allows (its own limits)
            failed.append(f"{name}: {exc}")
            continue
        changed += 1
        print(f"{name} {_fmt(link, name, old)} → {_fmt(link, name, new)}")
    for line in failed:
        print(f"quadgcs params: load {path}: {line}", file=sys.stderr)
    print(f"loaded {path}: {changed} changed, {unchanged} unchanged, {len(failed)} failed "
          f"of {len(wanted)}")
    return 1 if failed else 0


def _diff(link: VehicleLink, path: Path, wanted: dict[str, float]) -> int:
    current = link.fetch_params()
    types = {n: t for n in current if (t := link.param_type(n)) is not None}
    only_vehicle = 0
    for d in diff_params(current, wanted, types):
        if d.file is None:
            only_vehicle += 1
        elif d.vehicle is None:
            print(f"{d.name} not on the vehicle (file {format_param_value(d.file)})")
        else:
            print(f"{d.name} {_fmt(link, d.name, d.vehicle)} "
                  f"(file {format_param_value(d.file, types.get(d.name))})")
    if only_vehicle:
        print(f"{only_vehicle} vehicle parameters are not in {path}")
    return 0


def run(args: argparse.Namespace) -> int:
    """Check the input, connect, do the action."""
    action = args.action
    if action is None:
        raise UsageError("expected an action: show, get, set, save, load or diff")
    name = _name(args.name) if action in ("get", "set") else ""
    if action == "show" and not _is_pattern(args.pattern):
        args.pattern = _name(args.pattern)
    value = _value(name, args.value) if action == "set" else 0.0
    wanted: dict[str, float] = {}
    if action in ("load", "diff"):
        wanted = read_parm_file(args.file)
        if not wanted:
            raise UsageError(f"{action} {args.file}: the file sets no parameter")
    if action == "save":
        _check_writable(args.file)
    with _vehicle(args) as link:
        if action == "show":
            return _show(link, args.pattern)
        if action == "get":
            print(f"{name} {_fmt(link, name, _read_one(link, name))}")
            return 0
        if action == "set":
            return _set(link, name, value)
        if action == "save":
            return _save(link, args.file)
        if action == "load":
            return _load(link, args.file, wanted)
        return _diff(link, args.file, wanted)
