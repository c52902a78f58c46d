"""Hashes of fixed lockstep recordings: a refactor that keeps behaviour keeps every one.

Flies each fixed seed in lockstep (the same flight for the same seed, whatever the machine's
load), then hashes every recorded message (topic, log time, publish time, bytes) per topic and
the printed summary without its wall-clock and path fields. Run it before and after a change
and compare:

    python bench/recording_hashes.py --out before.json
    python bench/recording_hashes.py --out after.json --against before.json

Exit status 1 when `--against` differs.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

ROOT = Path(__file__).resolve().parent.parent

FLIGHTS: dict[str, list[str]] = {
    "hold-apm25-seed3": ["fly", "--lockstep", "--profile", "apm25", "--seed", "3",
                         "--alt", "1.0", "--hold", "20"],
    "hold-copter4-seed5": ["fly", "--lockstep", "--profile", "copter4", "--seed", "5",
                           "--alt", "1.0", "--hold", "20", "--fix-failsafe"],
    "step-apm25-seed7": ["fly", "--lockstep", "--profile", "apm25", "--seed", "7",
                         "--alt", "1.0", "--hold", "10", "--step", "0.3"],
    "epbha-seed1": ["mission", "run", "missions/epbha_table.toml", "--lockstep", "--seed", "1"],
    "flock-seed2": ["mission", "run", "missions/flock_table.toml", "--lockstep", "--seed", "2"],
}
"""Name → the quadgcs arguments that fly it (a recording path is added)."""

WALL_KEYS = frozenset({"wall_s", "recording", "recordings", "plot", "elapsed_wall_s"})
"""Summary fields that name paths or wall-clock time, which differ run to run by design."""


def _scrub(value: object) -> object:
    if isinstance(value, dict):
        return {k: _scrub(v) for k, v in sorted(value.items()) if k not in WALL_KEYS}
    if isinstance(value, list):
        return [_scrub(v) for v in value]
    return value


def recording_digest(paths: list[Path]) -> dict[str, str]:
    """Topic → sha256 of its messages, over every recording in `paths` (sorted by name)."""
    digests: dict[str, Any] = {}
    for rank, path in enumerate(sorted(paths)):
        # A recording's name carries its wall-clock start; its rank and vehicle do not.
        vehicle = path.stem.rsplit("_", 1)[-1]
        with path.open("rb") as f:
            for _schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
                key = f"{rank}-{vehicle}:{channel.topic}"
                h = digests.setdefault(key, hashlib.sha256())
                h.update(message.log_time.to_bytes(8, "little"))
                h.update(message.publish_time.to_bytes(8, "little"))
                data = message.data
                if channel.topic.endswith("/summary"):
                    # The mission's summary carries the run's wall-clock time.
                    data = json.dumps(_scrub(json.loads(data)), sort_keys=True).encode()
                h.update(data)
    return {k: v.hexdigest() for k, v in sorted(digests.items())}


def fly(name: str, args: list[str], workdir: Path) -> dict[str, Any]:
    """Fly one fixed flight; its summary's and recordings' hashes."""
    out = workdir / name
    out.mkdir()
    cmd = [sys.executable, "-m", "lab", *args, "-o", str(out), "--json"]
    if args[0] == "mission":
        cmd.append("--quiet")
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
    try:
        summary = _scrub(json.loads(done.stdout))
    except json.JSONDecodeError:
        summary = {"stdout": done.stdout.strip()[-400:]}
    topics = recording_digest(list(out.glob("**/*.mcap")))
    whole = hashlib.sha256(json.dumps([summary, topics], sort_keys=True).encode()).hexdigest()
    return {"exit": done.returncode, "hash": whole,
            "summary": hashlib.sha256(json.dumps(summary, sort_keys=True).encode()).hexdigest(),
            "topics": topics}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, help="write the hashes here as JSON")
    p.add_argument("--against", type=Path, help="compare with an earlier --out file")
    p.add_argument("--only", action="append", choices=sorted(FLIGHTS), help="fly only these")
    args = p.parse_args(argv)
    names = args.only or list(FLIGHTS)
    with tempfile.TemporaryDirectory() as tmp:
        result = {name: fly(name, FLIGHTS[name], Path(tmp)) for name in names}
    for name, r in result.items():
        print(f"{name:20s} exit {r['exit']}  {r['hash']:.16s}  ({len(r['topics'])} topics)")
    if args.out:
        args.out.write_text(json.dumps(result, indent=1, sort_keys=True))
    if args.against is None:
        return 0
    before = json.loads(args.against.read_text())
    differ = 0
    for name, r in result.items():
        old = before.get(name)
        if old is None:
            print(f"{name}: not in {args.against}")
            continue
        if old["hash"] == r["hash"]:
            continue
        differ += 1
        changed = sorted(t for t in set(old["topics"]) | set(r["topics"])
                         if old["topics"].get(t) != r["topics"].get(t))
        print(f"{name}: DIFFERS (summary {'same' if old['summary'] == r['summary'] else 'differs'}"
              f"; {len(changed)} topics, first {changed[:3]})")
    print("identical" if differ == 0 else f"{differ} of {len(result)} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
