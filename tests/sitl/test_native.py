"""The compiled SITL (sitl.native): used only while it matches its sources, and flying bit for
bit what the interpreted SITL flies."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from logs import open_recording
from sitl import native

SOURCE = "sitl/physics.py"


def _tree(tmp_path: Path, text: str = "X = 1\n") -> Path:
    (tmp_path / "sitl").mkdir()
    (tmp_path / SOURCE).write_text(text, encoding="utf-8")
    return tmp_path


def _manifest(root: Path, **fields: object) -> Path:
    data: dict[str, object] = {
        "cache_tag": sys.implementation.cache_tag,
        "sources": {SOURCE: native.digest(root / SOURCE)},
    }
    data.update(fields)
    path = root / "sitl" / native.MANIFEST.name
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def test_current_compiled_modules_are_used(tmp_path: Path) -> None:
    root = _tree(tmp_path)
    assert native.why_interpreted(root, _manifest(root), {}) is None


def test_an_edited_source_sends_the_whole_sitl_back_to_source(tmp_path: Path) -> None:
    root = _tree(tmp_path)
    manifest = _manifest(root)
    (root / SOURCE).write_text("X = 2\n", encoding="utf-8")
    why = native.why_interpreted(root, manifest, {})
    assert why is not None and SOURCE in why and "changed" in why


@pytest.mark.parametrize(("fields", "env", "expected"), [
    ({}, {native.ENV_SWITCH: "0"}, "QUADGCS_SITL_NATIVE=0"),
    ({"cache_tag": "cpython-99"}, {}, "cpython-99"),
    ({"sources": {}, "skipped": "no C compiler on this machine"}, {}, "no C compiler"),
    ({"sources": {"sitl/gone.py": "0" * 64}}, {}, "sitl/gone.py is gone"),
])
def test_why_the_sitl_runs_interpreted_is_said(tmp_path: Path, fields: dict[str, object],
                                               env: dict[str, str], expected: str) -> None:
    root = _tree(tmp_path)
    why = native.why_interpreted(root, _manifest(root, **fields), env)
    assert why is not None and expected in why


def test_a_missing_or_broken_manifest_means_interpreted(tmp_path: Path) -> None:
    root = _tree(tmp_path)
    path = root / "sitl" / native.MANIFEST.name
    assert "not built" in (native.why_interpreted(root, path, {}) or "")
    path.write_text("{not json", encoding="utf-8")
    assert "unreadable" in (native.why_interpreted(root, path, {}) or "")


def test_every_compiled_source_is_listed_and_no_package_init() -> None:
    files = native.sources()
    assert Path("sitl/physics.py") in files and Path("sitl/autopilot/autopilot.py") in files
    assert all(p.name != "__init__.py" for p in files)
    assert all((native.ROOT / p).is_file() for p in files)


def _why_not_built() -> str | None:
    return native.why_interpreted(native.ROOT, native.MANIFEST, {})


def _built() -> bool:
    return _why_not_built() is None


def _status(env: dict[str, str]) -> str:
    proc = subprocess.run([sys.executable, "-m", "sitl.native_build", "status"],
                          capture_output=True, text=True, timeout=60, check=True,
                          env={**os.environ, **env})
    return proc.stdout.strip()


def test_the_switch_loads_every_module_from_source() -> None:
    assert _status({native.ENV_SWITCH: "0"}) == "interpreted SITL (QUADGCS_SITL_NATIVE=0)"
    if _built():
        assert _status({}) == "compiled SITL (mypyc)"


def _fly(out: Path, env: dict[str, str]) -> list[tuple[str, int, bytes]]:
    proc = subprocess.run(
        [sys.executable, "-m", "lab", "fly", "--lockstep", "--seed", "4", "--hold", "5",
         "--json", "-o", str(out)],
        capture_output=True, text=True, timeout=120, check=False,
        env={**os.environ, **env})
    assert proc.returncode == 0, proc.stderr.strip()[-400:]
    rec = open_recording(out)
    # every byte the SITL sent and the station sent back, and the SITL's truth, with times
    return list(rec.raw_messages(["/mavlink/rx", "/mavlink/tx", "/vehicle/sim_truth"]))


@pytest.mark.e2e
@pytest.mark.skipif(not _built(), reason=f"no compiled SITL to compare: {_why_not_built()}")
def test_the_compiled_sitl_flies_the_interpreted_flight_bit_for_bit(tmp_path: Path) -> None:
    fast = _fly(tmp_path / "compiled.mcap", {})
    slow = _fly(tmp_path / "interpreted.mcap", {native.ENV_SWITCH: "0"})
    assert len(fast) > 1000
    assert fast == slow


def test_with_no_compiler_the_build_says_so_and_the_sitl_runs_interpreted(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    from sitl import native_build

    root = _tree(tmp_path)
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    assert native_build.build(root) == 0
    assert "no C compiler" in capsys.readouterr().out
    why = native.why_interpreted(root, root / "sitl" / native.MANIFEST.name, {})
    assert why is not None and "no C compiler" in why
