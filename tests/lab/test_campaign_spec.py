"""Campaign files: what they plan, and bad ones as one line naming the file, key and expected."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.config import config_from_table
from lab.campaign import CampaignError, load_campaign
from lab.campaign.plan import plan_runs
from lab.campaign.tables import dumps, read_table
from lab.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "c.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_grid_plans_every_combination_with_stable_ids(tmp_path: Path) -> None:
    c = load_campaign(_file(tmp_path, """
[axes]
"station.altitude.gains.kp" = [3.0, 4.0]
seed = { range = [1, 3] }
"world.sensors.sonar.noise_m" = [0.01]
"""))
    runs = plan_runs(c)
    assert len(runs) == 6 and len({r.run_id for r in runs}) == 6
    assert [r.run_id for r in plan_runs(c)] == [r.run_id for r in runs]
    assert runs[0].values == {"station.altitude.gains.kp": 3.0, "seed": 1,
                              "world.sensors.sonar.noise_m": 0.01}


def test_a_random_campaign_draws_its_samples_from_its_seed(tmp_path: Path) -> None:
    text = """
kind = "random"
samples = 5
sample_seed = 3
[axes]
"station.altitude.gains.kp" = { min = 2.0, max = 6.0 }
seed = { min = 0, max = 1000 }
world = ["../../worlds/empty_room.toml"]
"""
    path = _file(tmp_path, text.replace("../../worlds", str(ROOT / "worlds")))
    a, b = plan_runs(load_campaign(path)), plan_runs(load_campaign(path))
    assert [r.values for r in a] == [r.values for r in b]
    assert all(2.0 <= r.values["station.altitude.gains.kp"] <= 6.0 for r in a)
    assert all(isinstance(r.values["seed"], int) for r in a)
    assert len({r.values["seed"] for r in a}) == 5


@pytest.mark.parametrize(("text", "needle"), [
    ('[axes]\n"station.altitude.gains.kq" = [1.0]',
     "axes.station.altitude.gains.kq[0]: station altitude.gains.kq: unknown key; expected one"),
    ('[axes]\nwind = [1.0]', "axes.wind: unknown axis; expected seed, profile, world"),
    ('[axes]\nseed = []', "axes.seed: empty list; expected at least one value"),
    ("kind = 'grid'", "axes: empty; expected at least one axis with values"),
    ('[axes]\n"station.altitude.gains.kp" = ["high"]',
     "axes.station.altitude.gains.kp[0]: station altitude.gains.kp: expected a number, got "
     "'high'"),
    ('[axes]\n"world.sensors.sonar.noise_m" = [true]', "axes.world.sensors.sonar.noise_m[0]: "),
    ('[axes]\nseed = [1.5]', "axes.seed[0]: expected an integer >= 0, got 1.5"),
    ('[axes]\nworld = ["nowhere.toml"]', "axes.world[0]: no such world file"),
    ('mission = "no/such/mission.toml"', "mission: no such mission file"),
    ('mission = "MISSIONS/epbha_table.toml"\n[fly]\nalt_m = 1.0',
     "fly: a campaign flies a mission file or a [fly] table, not both"),
    ('mission = "MISSIONS/epbha_table.toml"\nkind = "search"',
     "kind: a search tunes [fly] flights"),
    ('mission = "MISSIONS/epbha_table.toml"\n[axes]\nprofile = ["apm25"]',
     "axes.profile: unknown axis; a mission campaign varies seed and planner.KEY"),
    ('mission = "MISSIONS/epbha_table.toml"\n[axes]\n"planner.step_m" = ["long"]',
     "axes.planner.step_m[0]: "),
    ('mission = "MISSIONS/epbha_table.toml"\n[axes]\n"planner.wings" = [2]',
     "axes.planner.wings[0]: "),
    ('[fly]\nalt_m = 9.0', "fly: altitude 9.0 m outside 0.2..3.5 m"),
    ('[fly]\nwind = 1', "fly.wind: unknown key; expected one of"),
    ('kind = "sweep"', "kind: expected one of ['grid', 'random', 'search'], got 'sweep'"),
    ('[axes]\nseed = {min = 1, max = 3}', "axes.seed: expected a list of values, {range"),
    ('kind = "search"\n[axes]\n"station.altitude.gains.kp" = {min = 1.0, max = 2.0}',
     "search: missing; kind = \"search\" needs a [search] table"),
    ('kind = "search"\n[axes]\nseed = [1]\n[search]\ntrials = 2',
     "axes.seed: a search varies station.KEY and fly.KEY axes"),
    ('kind = "search"\n[axes]\n"station.altitude.gains.kp" = [1.0]\n[search]\nobjective = "x"',
     "search.objective: expected one of ['rms_error_m'"),
    ("axes = 3 = 4", "not valid TOML"),
    ('[axes]\n"link.fade" = ["sideways"]',
     "axes.link.fade[0]: fade 'sideways': expected one of none, down, up, both"),
    ('[axes]\n"link.jitter" = [1.0]', "axes.link.jitter: unknown axis; expected link.{loss"),
])
def test_bad_files_are_one_line(tmp_path: Path, text: str, needle: str) -> None:
    path = _file(tmp_path, text.replace("MISSIONS", str(ROOT / "missions")))
    with pytest.raises(CampaignError) as err:
        load_campaign(path)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: ") and needle in msg, msg


def test_cli_bad_file_and_unreachable_address(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    bad = _file(tmp_path, "[axes]\nseed = []")
    assert main(["campaign", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"quadgcs campaign: {bad}: axes.seed: empty list; expected at least one value"
    good = _file(tmp_path, "[axes]\nseed = [1]")
    assert main(["campaign", str(good), "--address", "127.0.0.1:1"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith("quadgcs campaign: --address 127.0.0.1:1: no Ray cluster answers there")


def test_a_written_station_table_reads_back_as_the_same_config(tmp_path: Path) -> None:
    table = {"estimator_kind": "complementary",
             "altitude": {"gains": {"kp": 3.25, "setpoint_slew_per_s": 0.5},
                          "hover_max": 0.7}}
    path = tmp_path / "s.toml"
    path.write_text(dumps(table, "a header\nof two lines"), encoding="utf-8")
    assert path.read_text().startswith("# a header\n# of two lines\n")
    assert read_table(path) == table
    assert config_from_table(read_table(path)) == config_from_table(table)
