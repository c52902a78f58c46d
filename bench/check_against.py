"""`logs check --against` on the 60-seed hold campaign (campaigns/hold_check_seeds.toml): how
many metrics flag a flight flown with the campaign's own settings, and one with half the
altitude kp, on seeds inside the campaign and on fresh ones.

    python bench/check_against.py [--campaign OUT] [--fresh 61-70]

OUT is the campaign's output directory; without results there, the campaign is flown first
(lockstep, on this machine's cores: about 6 CPU-minutes). Prints one line per flight: the
metrics flagged beyond the campaign's worst run, and hold.error_memory_s's percentile.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/ shadows packages

from gcs.commands.logs_check import campaign_settings
from gcs.flight_check import gather_file
from lab.campaign.results import RESULTS_NAME, read_results
from lab.campaign.run import fly_run, make_run
from lab.campaign.spec import load_campaign
from lab.campaign.types import BaseFlight
from lab.cli import main as quadgcs
from logs.check import load_thresholds, measure
from logs.check.against import place, settings_differences

ROOT = Path(__file__).resolve().parents[1]
CAMPAIGN = ROOT / "campaigns" / "hold_check_seeds.toml"
HALF_KP = {"station.altitude.gains.kp": 4.5}  # the station's default is 9.0


def _range(text: str) -> list[int]:
    a, _, b = text.partition("-")
    return list(range(int(a), int(b or a) + 1))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--campaign", type=Path,
                   default=ROOT / "flights" / "campaigns" / "hold_check_seeds")
    p.add_argument("--inside", default="7,30", help="campaign seeds to fly again (default 7,30)")
    p.add_argument("--fresh", default="61-70", help="seeds outside the campaign (default 61-70)")
    args = p.parse_args()
    if not (args.campaign / RESULTS_NAME).is_file():
        quadgcs(["campaign", str(CAMPAIGN), "-o", str(args.campaign), "--quiet"])
    rows = read_results(args.campaign / RESULTS_NAME)
    base = load_campaign(CAMPAIGN).base
    assert isinstance(base, BaseFlight)
    table = load_thresholds(None)
    settings = campaign_settings(args.campaign, rows) or {}
    seeds = [(int(s), "inside") for s in args.inside.split(",")] + \
        [(s, "fresh") for s in _range(args.fresh)]
    print(f"campaign {args.campaign}: {sum(r.get('status') == 'ok' for r in rows)} runs flown")
    with tempfile.TemporaryDirectory() as tmp:
        for seed, where in seeds:
            for label, extra in (("own settings", {}), ("half kp", HALF_KP)):
                run = make_run(base, {"seed": seed, **extra})
                row = fly_run(base, run, Path(tmp), "bench")
                if row["status"] != "ok":
                    print(f"seed {seed:3d} ({where}) {label:12s}: failed: {row['reason']}")
                    continue
                fs = gather_file(Path(tmp) / "flights" / f"{run.run_id}.mcap")
                placed = place(measure(fs), rows, table)
                differ = settings_differences(fs.setup, settings)
                flagged = [pl.key for pl in placed if pl.flagged]
                memory = next(pl for pl in placed if pl.key == "hold.error_memory_s")
                print(f"seed {seed:3d} ({where}) {label:12s}: {len(flagged)} flagged "
                      f"{flagged}; error memory {memory.value:.3f} s, percentile "
                      f"{memory.percentile:.0f} (campaign {memory.campaign_best:.3f}-"
                      f"{memory.campaign_worst:.3f} s); settings differ: {differ or 'no'}")


if __name__ == "__main__":
    main()
