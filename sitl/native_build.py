"""Compile the SITL's hot modules with mypyc, in place (see `sitl.native` for why and how
they are used).

    python -m sitl.native_build build | clean | status

`build` exits 0 when it compiled, or when this machine has no C compiler or no mypyc (it says
so: the SITL then runs interpreted); 1 when mypyc or the compiler failed on our code, which
`make` reports.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Sequence
from pathlib import Path

from sitl.native import GROUP, MANIFEST, ROOT, describe, digest, sources


def _built_files(root: Path) -> list[Path]:
    """The extension modules under `root/sitl`."""
    suffixes = tuple(importlib.machinery.EXTENSION_SUFFIXES)
    return [p for p in (root / "sitl").rglob("*") if p.name.endswith(suffixes)]


def _manifest(root: Path) -> Path:
    return root / "sitl" / MANIFEST.name


def clean(root: Path = ROOT) -> int:
    """Remove the compiled modules and the manifest; how many files went."""
    gone = _built_files(root)
    for p in gone:
        p.unlink()
    _manifest(root).unlink(missing_ok=True)
    return len(gone)


def _compiler() -> str | None:
    cc = (sysconfig.get_config_var("CC") or "cc").split()[0]
    return shutil.which(os.environ.get("CC", cc).split()[0])


def _write_manifest(root: Path, data: dict[str, object]) -> None:
    _manifest(root).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")


def build(root: Path = ROOT, jobs: int = 2) -> int:
    """Compile `COMPILED` in place; 0 when built, or skipped for want of mypyc or a compiler."""
    clean(root)
    files = sources(root)
    why = ("mypyc is not installed (it comes with mypy: the dev extra)"
           if importlib.util.find_spec("mypyc") is None else
           "no C compiler on this machine" if _compiler() is None else None)
    if why is not None:
        _write_manifest(root, {"skipped": why, "sources": {}})
        print(f"sitl.native: {why}: the SITL runs interpreted")
        return 0
    hashes = {p.as_posix(): digest(root / p) for p in files}
    with tempfile.TemporaryDirectory(prefix="sitl-native-") as tmp:
        script = (
            "from setuptools import setup\n"
            "from mypyc.build import mypycify\n"
            f"mods = mypycify({[p.as_posix() for p in files]!r}, group_name={GROUP!r},\n"
            f"                multi_file=True, target_dir={tmp + '/c'!r})\n"
            # multi_file writes a dotted group's header one folder down from its includes
            f"for m in mods: m.include_dirs.append({tmp + '/c/sitl'!r})\n"
            "setup(name='quadgcs-sitl-native', ext_modules=mods, script_args=[\n"
            f"    'build_ext', '--inplace', '-j', '{jobs}', '--build-temp', {tmp + '/o'!r}])\n"
        )
        proc = subprocess.run([sys.executable, "-c", script], cwd=root, capture_output=True,
                              text=True, check=False)
    if proc.returncode != 0:
        clean(root)
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-15:]
        print("sitl.native: mypyc failed; the SITL would run interpreted:\n  "
              + "\n  ".join(tail), file=sys.stderr)
        return 1
    _write_manifest(root, {"cache_tag": sys.implementation.cache_tag, "sources": hashes})
    print(f"sitl.native: compiled {len(files)} SITL modules ({len(_built_files(root))} "
          "extension files)")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if args == ["build"]:
        return build()
    if args == ["clean"]:
        print(f"sitl.native: removed {clean()} compiled files")
        return 0
    if args == ["status"]:
        print(describe())
        return 0
    print("usage: python -m sitl.native_build build | clean | status", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
