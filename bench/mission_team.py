"""A team mission on the bundled SITL in real time: bring-up, arming, take-off, CPU.

Flies `missions/flock_table.toml` (five vehicles) at 1x as a user runs it and prints, from the
report and each vehicle's recording: when each vehicle's pre-flight checks passed, how far apart
the vehicles armed, how long each stood armed on the floor before its take-off (the firmware
disarms after 15 s on 3.2.1), the outcome, and the CPU the station and the SITL used together
(in cores: CPU seconds over wall seconds).

    .venv/bin/python bench/mission_team.py [--speedup 1] [--seed 3] [--mission FILE]

With `--mission missions/radiation_3src.toml` it also prints the map's samples, IoU (and what
it was scored against) and the sources enclosed.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from logs import open_recording  # noqa: E402


def _first_states(path: str) -> tuple[dict[str, float], float | None]:
    """Station time of each supervisor state's first entry, and of the pre-flight verdict."""
    rec = open_recording(path)
    first: dict[str, float] = {}
    for _, _, m in rec.messages(["/gcs/supervisor"]):
        first.setdefault(m["state"], m["t_s"])
    pre = next((m["t_s"] for _, _, m in rec.messages(["/gcs/events"])
                if m["text"].startswith("pre-flight")), None)
    return first, pre


def main() -> int:
    """Fly once and print the numbers."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mission", type=Path, default=ROOT / "missions" / "flock_table.toml")
    ap.add_argument("--speedup", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as out:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        wall0 = time.monotonic()
        proc = subprocess.run(
            [sys.executable, "-m", "gcs", "mission", "run", str(args.mission), "--speedup",
             str(args.speedup), "--seed", str(args.seed), "--json", "-o", out],
            capture_output=True, text=True, check=False, cwd=ROOT)
        wall = time.monotonic() - wall0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        lines = proc.stdout.strip().splitlines()
        if not lines:
            print(f"mission exited {proc.returncode}: {proc.stderr.strip()}")
            return 1
        d = json.loads(lines[-1])
        print(f"mission {d['mission']} at {args.speedup:g}x, seed {args.seed}: {d['status']} "
              f"({d['reason']}), exit {proc.returncode}")
        print(f"  collisions {d['collisions']} (source {d.get('collision_source')}, "
              f"{d.get('truth_samples')} truth samples), min separation "
              f"{d.get('min_separation_m')} m")
        print(f"  mission time {d['duration_s']} s, wall {wall:.1f} s; station + SITL CPU "
              f"{cpu:.1f} s = {cpu / wall:.2f} cores")
        if d.get("samples") is not None:  # a radiation map: how good, against what
            print(f"  {d['samples']} samples, IoU {d.get('iou')} ({d.get('score_source')}), "
                  f"sources enclosed {d.get('sources_enclosed')}/{d.get('sources_total')}")
        states = [_first_states(p) for p in d.get("recordings") or [d["recording"]]]
        t0 = min(pre for _, pre in states if pre is not None)
        armed = [s["manual"] for s, _ in states if "manual" in s]
        for k, (s, pre) in enumerate(states, start=1):
            on_floor = s.get("takeoff", float("nan")) - s.get("manual", float("nan"))
            ready = f"{pre - t0:5.2f}" if pre is not None else "  -  "
            print(f"  vehicle {k}: pre-flight at +{ready} s, armed on the floor "
                  f"{on_floor:5.2f} s before take-off")
        if armed:
            print(f"  arming spread {max(armed) - min(armed):.2f} s (station time)")
    return 0 if proc.returncode == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
