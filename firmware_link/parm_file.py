"""`.parm` parameter files as MAVProxy, Mission Planner and QGroundControl write them.

Read (one parameter a line):
- `NAME VALUE`, any whitespace between (MAVProxy, ArduPilot's own defaults files);
- `NAME,VALUE` (Mission Planner);
- `SYSID<TAB>COMPID<TAB>NAME<TAB>VALUE<TAB>TYPE` (QGroundControl's .params);
- `#` starts a comment to the end of the line; blank lines are skipped.
Every error names file:line, what was found and what is expected. A name given twice is an
error naming both lines: a file loaded onto a vehicle must say one thing per parameter.

Written: `NAME VALUE` sorted by name, integer parameters as integers and floats as the
shortest text that reads back as the same float32, the precision the vehicle holds.
"""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from firmware_link.errors import LinkUsageError
from firmware_link.params import INT_RANGES, PARAM_NAME_MAX, as_float32, same_param_value

_NAME = re.compile(rf"^[A-Z][A-Z0-9_]{{0,{PARAM_NAME_MAX - 1}}}$")
EXPECTED_LINE = "expected NAME VALUE or NAME,VALUE"


class ParmFileError(LinkUsageError):
    """A parameter file that cannot be read or written, or a line in it that is malformed."""


def _where(source: str, line_no: int) -> str:
    return f"{source}:{line_no}"


def _check_name(name: str, where: str) -> str:
    if _NAME.match(name):
        return name
    if len(name) > PARAM_NAME_MAX:
        raise ParmFileError(
            f"{where}: parameter name {name!r} has {len(name)} characters; at most "
            f"{PARAM_NAME_MAX}"
        )
    raise ParmFileError(
        f"{where}: parameter name {name!r}: expected upper-case letters, digits and _ "
        f"(as ArduPilot names them)"
    )


def _parse_value(text: str, name: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ParmFileError(f"{where}: {name} value {text!r} is not a number") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise ParmFileError(f"{where}: {name} value {text!r} is not a finite number")
    return value


def _fields(line: str) -> list[str]:
    if "\t" in line:
        tabbed = [f.strip() for f in line.split("\t") if f.strip()]
        if len(tabbed) == 5 and tabbed[0].isdigit() and tabbed[1].isdigit():
            return tabbed[2:4]  # QGroundControl: sysid, compid, name, value, type
    if "," in line:
        return [f.strip() for f in line.split(",")]
    return line.split()


def parse_parm(text: str, source: str = "<parameters>") -> dict[str, float]:
    """The parameters of a file's text, in file order; ParmFileError naming `source`:line."""
    out: dict[str, float] = {}
    first_line: dict[str, int] = {}
    for line_no, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        where = _where(source, line_no)
        fields = _fields(line)
        if len(fields) != 2 or not all(fields):
            raise ParmFileError(f"{where}: {line!r}: {EXPECTED_LINE}")
        name = _check_name(fields[0], where)
        value = _parse_value(fields[1], name, where)
        if name in first_line:
            raise ParmFileError(
                f"{where}: {name} is already set on line {first_line[name]}; give each "
                f"parameter once"
            )
        first_line[name] = line_no
        out[name] = value
    return out


def read_parm_file(path: Path | str) -> dict[str, float]:
    """Parse a parameter file; ParmFileError for a missing, unreadable or malformed one."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ParmFileError(f"{p}: no such file") from None
    except IsADirectoryError:
        raise ParmFileError(f"{p}: is a directory, not a parameter file") from None
    except UnicodeDecodeError:
        raise ParmFileError(f"{p}: not a text file ({EXPECTED_LINE} lines)") from None
    except OSError as exc:
        raise ParmFileError(f"{p}: cannot read: {exc.strerror or exc}") from None
    return parse_parm(text, str(p))


def format_param_value(value: float, ptype: int | None = None) -> str:
    """A value as a file or a pilot reads it: integers whole, floats at float32 precision."""
    if ptype in INT_RANGES:
        return str(round(value))
    f = as_float32(value)
    if f == 0.0:
        return "0"
    for digits in range(1, 10):
        text = f"{f:.{digits}g}"
        if as_float32(float(text)) == f:
            break
    if "e" in text and 1e-4 <= abs(f) < 1e16:
        text = format(Decimal(text), "f")  # 4.5e+03 reads better as 4500
    return text


def render_parm(
    params: Mapping[str, float],
    types: Mapping[str, int] | None = None,
    header: Iterable[str] = (),
) -> str:
    """A parameter file's text: `# header` lines, then `NAME VALUE` lines sorted by name."""
    kinds = types or {}
    lines = [f"# {h}" for h in header]
    lines += [f"{n} {format_param_value(params[n], kinds.get(n))}" for n in sorted(params)]
    return "\n".join(lines) + "\n"


def write_parm_file(
    path: Path | str,
    params: Mapping[str, float],
    types: Mapping[str, int] | None = None,
    header: Iterable[str] = (),
) -> None:
    """Write a parameter file whole or not at all (a temporary file renamed into place)."""
    p = Path(path)
    text = render_parm(params, types, header)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=p.parent if str(p.parent) else ".")
    except OSError as exc:
        raise ParmFileError(f"{p}: cannot write: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, p)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise ParmFileError(f"{p}: cannot write: {exc.strerror or exc}") from None


@dataclass(frozen=True, slots=True)
class ParamDiff:
    """One parameter that differs: its value on the vehicle and in the file (None: absent)."""

    name: str
    vehicle: float | None
    file: float | None


def diff_params(
    vehicle: Mapping[str, float],
    file: Mapping[str, float],
    types: Mapping[str, int] | None = None,
) -> list[ParamDiff]:
    """Parameters whose values differ (at the precision of their type) or that only one side
    has, sorted by name."""
    kinds = types or {}
    out: list[ParamDiff] = []
    for name in sorted(set(vehicle) | set(file)):
        v, f = vehicle.get(name), file.get(name)
        if v is not None and f is not None and same_param_value(v, f, kinds.get(name)):
            continue
        out.append(ParamDiff(name, v, f))
    return out
