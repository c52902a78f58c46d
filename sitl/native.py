"""The SITL's hot modules compiled to C by mypyc: the same source, run as native code.

An interpreted lockstep flight spends about half its CPU in the SITL (physics, sensors,
autopilot, telemetry packing), scalar Python on typed classes; compiled, the whole flight costs
a quarter less CPU (`bench/campaign.py`). The compiled SITL flies bit for bit the flight the
interpreted one flies (a test compares every byte it sends).

- `python -m sitl.native_build build` compiles `COMPILED` in place (`make` does it) and writes
  `MANIFEST`: each source's SHA-256 as compiled. No C compiler (or no mypyc): it says so and
  the SITL runs interpreted.
- At import (`sitl/__init__.py` calls `guard`) the compiled modules are used only while every
  source still matches the manifest; an edited source, or `QUADGCS_SITL_NATIVE=0`, puts a finder
  first that loads every `sitl` module from source. All or none: compiled modules call each
  other natively, so one fresh source beside stale neighbours would still run the old code.
- Only the SITL: the station stays interpreted. Compiled classes refuse attributes they do not
  declare and check argument types at run time, and a station that raised on a loose type in
  the middle of a flight would put a vehicle at risk; the SITL only ever flies simulations.

Building is `sitl.native_build`'s.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = Path(__file__).resolve().parent / "_native.json"
ENV_SWITCH = "QUADGCS_SITL_NATIVE"
GROUP = "sitl._native"  # the shared library lands in the package, not beside it

# What a lockstep tick runs, and what mypyc compiles as it is. Left out: lockstep.py and the
# endpoints (they subclass built-in types), link/codec.py (it adds attributes at run time).
COMPILED = (
    "sitl/autopilot",
    "sitl/sensors",
    "sitl/battery.py",
    "sitl/companion.py",
    "sitl/geometry.py",
    "sitl/link/broadcast.py",
    "sitl/link/channel.py",
    "sitl/link/handler.py",
    "sitl/link/packer.py",
    "sitl/link/streams.py",
    "sitl/link/telemetry.py",
    "sitl/link/telemetry_full.py",
    "sitl/link/view.py",
    "sitl/mocap_server.py",
    "sitl/motors.py",
    "sitl/physics.py",
    "sitl/physics_state.py",
    "sitl/rotation.py",
    "sitl/simulation.py",
    "sitl/truth_server.py",
    "sitl/vehicle_model.py",
    "sitl/world.py",
)


def sources(root: Path = ROOT) -> list[Path]:
    """The compiled modules' source files, relative to `root`, sorted.

    Not a package's `__init__.py`: compiled, it would get a `__path__` (and its modules a
    `__file__`) one `sitl/` too deep, as the group's library lives in the package."""
    out: list[Path] = []
    for entry in COMPILED:
        path = root / entry
        out.extend(sorted(path.glob("*.py")) if path.is_dir() else [path])
    return sorted(p.relative_to(root) for p in out if p.name != "__init__.py")


def digest(path: Path) -> str:
    """A file's SHA-256, hex."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def why_interpreted(root: Path, manifest: Path, env: dict[str, str]) -> str | None:
    """Why the SITL must load from source (None: the compiled modules are current)."""
    if env.get(ENV_SWITCH, "1") == "0":
        return f"{ENV_SWITCH}=0"
    try:
        built = json.loads(manifest.read_text(encoding="utf-8"))
        hashes = built["sources"]
        tag = built.get("cache_tag")
    except FileNotFoundError:
        return "not built (make builds it)"
    except (OSError, ValueError, KeyError, TypeError) as exc:
        return f"{manifest.name} unreadable ({exc})"
    if not isinstance(hashes, dict) or not hashes:
        return str(built.get("skipped") or "nothing compiled")
    if tag != sys.implementation.cache_tag:
        return f"built for {tag}, running {sys.implementation.cache_tag}"
    for rel, want in sorted(hashes.items()):
        path = root / rel
        try:
            if digest(path) != want:
                return f"{rel} changed since it was compiled (make rebuilds it)"
        except OSError:
            return f"{rel} is gone"
    return None


class _SourceOnly:
    """A meta-path finder that loads `sitl.*` from .py files, never from extension modules."""

    def find_spec(self, fullname: str, path: Sequence[str] | None,
                  target: ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        if not fullname.startswith("sitl.") or path is None:
            return None
        details = (importlib.machinery.SourceFileLoader, importlib.machinery.SOURCE_SUFFIXES)
        for entry in path:
            spec = importlib.machinery.FileFinder(entry, details).find_spec(fullname, target)
            if spec is not None:
                return spec
        return None


REASON: str | None = "guard() not called"


def guard() -> None:
    """Load `sitl` from source unless the compiled modules match it (see the module's doc)."""
    global REASON
    REASON = why_interpreted(ROOT, MANIFEST, dict(os.environ))
    if REASON is not None and not any(isinstance(f, _SourceOnly) for f in sys.meta_path):
        sys.meta_path.insert(0, _SourceOnly())


def compiled(module: ModuleType) -> bool:
    """Whether `module` was loaded from an extension module."""
    origin = getattr(module, "__file__", None) or ""
    return origin.endswith(tuple(importlib.machinery.EXTENSION_SUFFIXES))


def build_kind() -> str:
    """"compiled" or "interpreted": which SITL this process runs (its CPU times depend on it)."""
    import sitl.physics

    return "compiled" if compiled(sitl.physics) else "interpreted"


def describe() -> str:
    """One line for benches and reports: which SITL this process runs, and why."""
    if build_kind() == "compiled":
        return "compiled SITL (mypyc)"
    return f"interpreted SITL ({REASON})" if REASON else "interpreted SITL"
