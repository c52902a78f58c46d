"""`kind = "fault-search"` campaign files: one-line errors, and a small search in this process
that leaves a row per run with its schedule and closest property, and for each violation a
shrunk schedule whose reproduction command flies the same verdict."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from lab.campaign.types import CampaignError
from lab.faultsearch.campaign import RESULTS, run_fault_campaign
from lab.faultsearch.schedule import load_schedule
from lab.faultsearch.spec import load_fault_campaign

ROOT = Path(__file__).resolve().parents[3]


def _file(tmp_path: Path, body: str) -> Path:
    p = tmp_path / "search.toml"
    p.write_text('kind = "fault-search"\n' + body, encoding="utf-8")
    return p


@pytest.mark.parametrize(("body", "key", "expected"), [
    ("", "runs", "missing; expected the budget"),
    ("runs = 10\n[faults]\nkinds = [\"fade_sideways\"]\n", "faults.kinds",
     "expected a non-empty list among fade_down"),
    ("runs = 10\n[faults]\nproperties = [\"pretty\"]\n", "faults.properties",
     "among overshoot, impact"),
    ("runs = 10\n[fly]\nprofile = \"px4\"\n", "fly.profile", "expected one of"),
    ("runs = 10\n[fly]\nhold = 3\n", "fly.hold", "unknown key"),
    ("runs = -3\n", "runs", "expected an integer >= 1"),
])
def test_a_bad_fault_search_file_is_one_line(tmp_path: Path, body: str, key: str,
                                             expected: str) -> None:
    path = _file(tmp_path, body)
    with pytest.raises(CampaignError) as info:
        load_fault_campaign(path)
    assert "\n" not in str(info.value)
    assert str(info.value).startswith(f"{path}: {key}: ")
    assert expected in str(info.value)


def test_the_shipped_searches_load() -> None:
    for name in ("fault_search_apm25", "fault_search_copter4"):
        c = load_fault_campaign(ROOT / "campaigns" / f"{name}.toml")
        assert c.runs >= 2000 and c.flight.profile in name


def test_a_small_search_keeps_every_run_and_replays_its_violations(tmp_path: Path) -> None:
    # a downlink fade in the hold's first second, a kill in the landing: runs that fail `fly`
    path = _file(tmp_path, 'runs = 3\nrandom_runs = 3\nshrink_runs = 1\n[faults]\n'
                 'kinds = ["fade_both", "pilot_kill"]\nanchors = ["hold", "step"]\n'
                 'max_length_s = 4.0\n')
    c = load_fault_campaign(path)
    rows, found = run_fault_campaign(c, tmp_path / "out", quiet=True)
    assert len(rows) == 3
    table = pq.read_table(tmp_path / "out" / RESULTS).to_pylist()
    assert [r["run"] for r in table] == [1.0, 2.0, 3.0]
    for r in table:
        assert r["property"] and r["margin"] == min(
            v for k, v in r.items() if k.startswith("margin.") and v == v)
        assert "[[fault]]" in r["schedule"] or r["faults"] == 0
    for v in found:  # each violation's shrunk schedule reads back and its command replays
        load_schedule(v.schedule)
        argv = v.command.split()[1:]
        done = subprocess.run([sys.executable, "-m", "lab", *argv, "--no-record"], cwd=ROOT,
                              capture_output=True, text=True, timeout=300, check=False)
        assert done.returncode in (0, 3), done.stderr
