"""The world file read once: the simulator and the station see the same room, boxes and starts,
and every reader of a TOML file fails in the same words."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.errors import UsageError
from gcs.mission.world import load_world as mission_world
from sitl.world import WorldError
from sitl.world import load_world as sitl_world
from worldfile import (
    TomlFileError,
    WorldFileError,
    load_world_file,
    parse_world,
    read_toml,
    vehicle_start,
)

ROOT = Path(__file__).resolve().parents[2]
WORLDS = [*sorted((ROOT / "worlds").glob("*.toml")),
          *sorted((ROOT / "missions" / "worlds").glob("*.toml"))]

OVER_A_BOX = """
name = "box_start"
start_positions = [[0.0, 0.0], [2.0, 2.0], [0.5, 0.5, 1.5]]
[room]
min = [-3.0, -3.0, 0.0]
max = [3.0, 3.0, 3.0]
[[boxes]]
name = "crate"
min = [-0.5, -0.5, 0.0]
max = [0.5, 0.5, 0.4]
"""


def write(tmp_path: Path, text: str, name: str = "w.toml") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.parametrize("path", WORLDS, ids=lambda p: p.name)
def test_simulator_and_station_read_a_shipped_world_alike(path: Path) -> None:
    sim = sitl_world(path)
    station = mission_world(path)
    assert station.start_positions_n == sim.start_positions_n
    assert station.world.room.min_n == sim.room_min_n
    assert station.world.room.max_n == sim.room_max_n
    assert [(b.name, b.min_n, b.max_n) for b in station.world.obstacles] == [
        (b.name, b.min_n, b.max_n) for b in sim.boxes]
    assert station.background_cps == sim.background_cps


def test_a_start_over_a_box_stands_on_it_for_both(tmp_path: Path) -> None:
    p = write(tmp_path, OVER_A_BOX)
    expected = ((0.0, 0.0, -0.4), (2.0, 2.0, 0.0), (0.5, 0.5, -1.5))
    assert sitl_world(p).start_positions_n == expected
    assert mission_world(p).start_positions_n == expected


def test_extra_vehicles_stand_in_a_row_east_of_the_last_start() -> None:
    starts = ((0.0, 0.0, 0.0), (1.0, 2.0, -0.4))
    assert vehicle_start(starts, 1) == (1.0, 2.0, -0.4)
    assert vehicle_start(starts, 2) == (1.0, 3.0, -0.4)
    assert vehicle_start(starts, 4) == (1.0, 5.0, -0.4)
    with pytest.raises(ValueError, match="vehicle index"):
        vehicle_start(starts, -1)


def test_the_station_is_as_strict_as_the_simulator(tmp_path: Path) -> None:
    p = write(tmp_path, OVER_A_BOX + "colour = 3\n")
    with pytest.raises(WorldError) as sim:
        sitl_world(p)
    with pytest.raises(UsageError) as station:
        mission_world(p)
    assert str(sim.value) == str(station.value) == (
        f"{p}: boxes[0].colour: unknown field (known: max, min, name)")


def test_a_nameless_world_is_named_after_its_file(tmp_path: Path) -> None:
    p = write(tmp_path, OVER_A_BOX.replace('name = "box_start"', ""), "attic.toml")
    assert load_world_file(p).name == "attic"
    assert parse_world({"room": {"min": [0, 0, 0], "max": [1, 1, 1]}}).name == "world"


@pytest.mark.parametrize(("content", "expected"), [
    (None, "no such world file"),
    (b"\xff\xfe\x00", "world file is not UTF-8 text"),
    (b"name = [", "not valid TOML ("),
])
def test_one_wording_for_a_bad_file(tmp_path: Path, content: bytes | None, expected: str) -> None:
    p = tmp_path / "bad.toml"
    if content is not None:
        p.write_bytes(content)
    for read, error in ((load_world_file, WorldFileError), (sitl_world, WorldError),
                        (mission_world, UsageError)):
        with pytest.raises(error) as exc:
            read(p)
        assert str(exc.value) == f"{p}: {expected}" or str(exc.value).startswith(
            f"{p}: {expected}")
    with pytest.raises(TomlFileError, match=f"^{tmp_path}: cannot read file"):
        read_toml(tmp_path)  # a directory
