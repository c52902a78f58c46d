"""World files read into the planners' NED world, and mission flight keys."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.errors import UsageError
from gcs.mission.spec import load_mission
from gcs.mission.world import load_world

ROOT = Path(__file__).resolve().parents[2]


def test_table_room_boxes_turn_into_ned() -> None:
    mw = load_world(ROOT / "worlds" / "table_room.toml")
    top = next(b for b in mw.world.obstacles if b.name == "table_top")
    assert top.min_n == (1.4, -0.4, -0.75) and top.max_n == (2.6, 0.4, -0.72)
    assert mw.world.room.min_n == (-3.0, -3.0, -3.0) and mw.world.room.max_n == (3.0, 3.0, 0.0)
    assert mw.start_positions_n[0] == (-1.5, 0.0, 0.0)
    assert not mw.sources
    # no truth to score against: the field is the background alone (0 cps by the 1 % rule)
    assert not mw.has_truth
    assert mw.radiation_field().intensity_at((0.0, 0.0)) == 0.0


def test_radiation_world_field_matches_its_sources() -> None:
    mw = load_world(ROOT / "worlds" / "radiation_3src.toml")
    field = mw.radiation_field(height_m=1.0)
    assert len(field.sources) == 3 and field.background_cps == 50.0
    # 1 m above a 5000 cps source (softened), plus the others and the background
    assert 5000.0 < field.intensity_at((-5.0, -4.0)) < 5400.0


def test_flock_world_starts_are_the_formation_slots() -> None:
    mw = load_world(ROOT / "missions" / "worlds" / "table_room_flock.toml")
    assert len(mw.start_positions_n) == 5
    xs = sorted({round(p[0], 3) for p in mw.start_positions_n})
    assert xs == [-2.586, -1.893, -1.2]


def test_flight_keys_and_their_errors(tmp_path: Path) -> None:
    base = '[planner]\nkind = "radiation"\n[flight]\n'
    f = tmp_path / "m.toml"
    f.write_text(base + "speedup = 2.5\nposition_tolerance_m = 0.1\nstep_timeout_s = 5\n")
    spec = load_mission(f)
    assert (spec.speedup, spec.position_tolerance_m, spec.step_timeout_s) == (2.5, 0.1, 5.0)
    f.write_text(base + "speedup = 80\n")
    with pytest.raises(UsageError, match=r"m.toml:4: flight.speedup: expected 0 < speedup <= 50"):
        load_mission(f)
    f.write_text(base + "settle_s = -1\n")
    with pytest.raises(UsageError, match=r"flight\.settle_s: expected a positive number"):
        load_mission(f)
