"""World files: shipped worlds load, bad files fail with one line naming file and field."""

from __future__ import annotations

from pathlib import Path

import pytest

from sitl.autopilot.profile import RcInput
from sitl.world import FloorMaterial, WorldError, default_world, load_world

WORLDS = Path(__file__).resolve().parents[2] / "worlds"

ROOM = """
name = "t"
[room]
min = [-3.0, -3.0, 0.0]
max = [3.0, 3.0, 3.0]
"""


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "x.toml"
    p.write_text(text, encoding="utf-8")
    return p


def error_of(tmp_path: Path, text: str) -> str:
    p = write(tmp_path, text)
    with pytest.raises(WorldError) as exc:
        load_world(p)
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith(f"{p}: ")
    return msg[len(f"{p}: ") :]


@pytest.mark.parametrize("name", ["empty_room", "table_room", "radiation_3src", "carpet_room"])
def test_shipped_worlds_load(name: str) -> None:
    w = load_world(WORLDS / f"{name}.toml")
    assert w.name == name
    assert w.mocap_enabled
    assert w.start_positions_n and all(p[2] == 0.0 for p in w.start_positions_n)


def test_file_coordinates_are_z_up_and_converted_to_ned() -> None:
    w = load_world(WORLDS / "table_room.toml")
    assert w.room_min_n == (-3.0, -3.0, -3.0) and w.floor_z_n == 0.0
    top = w.box("table_top")
    assert top.top_z_n == pytest.approx(-0.75)  # 0.75 m up
    goal = w.box("goal_box")
    # The goal box stands on the floor under the table's top.
    assert goal.max_n[2] == 0.0 and goal.min_n[2] > top.max_n[2]
    assert top.min_n[0] <= goal.min_n[0] and goal.max_n[0] <= top.max_n[0]
    assert top.min_n[1] <= goal.min_n[1] and goal.max_n[1] <= top.max_n[1]


def test_carpet_and_radiation_worlds() -> None:
    carpet = load_world(WORLDS / "carpet_room.toml")
    start = carpet.start_positions_n[0]
    assert carpet.floor_material(start[0], start[1]) is FloorMaterial.CARPET
    assert carpet.floor_material(2.5, 2.5) is FloorMaterial.HARD
    rad = load_world(WORLDS / "radiation_3src.toml")
    assert rad.room_max_n[0] - rad.room_min_n[0] == 20.0
    assert len(rad.sources) == 3 and len({s.strength_cps for s in rad.sources}) == 1


def test_start_without_height_stands_on_a_box(tmp_path: Path) -> None:
    text = "start_positions = [[0.0, 0.0], [2.0, 2.0]]\n" + ROOM
    text += '[[boxes]]\nname = "a"\nmin = [-1, -1, 0]\nmax = [1, 1, 0.4]\n'
    w = load_world(write(tmp_path, text))
    assert w.start_positions_n == ((0.0, 0.0, -0.4), (2.0, 2.0, 0.0))


def test_default_world_is_an_empty_room() -> None:
    w = default_world()
    assert w.boxes == () and w.sources == () and w.mocap_enabled
    assert w.room_max_n[0] - w.room_min_n[0] == 6.0


def test_overrides_reach_sensors_and_vehicle(tmp_path: Path) -> None:
    p = write(
        tmp_path,
        ROOM
        + """
[sensors.imu]
acc_noise_mps2 = 0.1
[sensors.sonar]
rate_hz = 10.0
[vehicle]
mass_kg = 1.7
[[sources]]
name = "s"
position = [1.0, 1.0, 0.0]
strength_cps = 2000.0
""",
    )
    w = load_world(p)
    assert w.sensors.imu.acc_noise_mps2 == 0.1
    assert w.sensors.sonar.rate_hz == 10.0
    assert w.sensors.baro.noise_m == default_world().sensors.baro.noise_m
    assert w.vehicle.mass_kg == 1.7
    assert w.background_cps == pytest.approx(20.0)  # 1 % of the strongest source


def test_autopilot_table_sets_the_receiver_and_the_gps(tmp_path: Path) -> None:
    """The failsafes' inputs (receiver, GPS fix, home distance) come from the world file; the
    defaults are a receiver at minimum and no GPS fix (indoors)."""
    plain = load_world(write(tmp_path, ROOM)).autopilot
    assert (plain.rc_input, plain.gps) == (RcInput.MIN, False)
    p = write(tmp_path, ROOM + '[autopilot]\nrc_input = "absent"\ngps = true\n'
              "home_distance_m = 1.5\n")
    a = load_world(p).autopilot
    assert (a.rc_input, a.gps, a.home_distance_m) == (RcInput.ABSENT, True, 1.5)


BAD = [
    (
        ROOM + '[[boxes]]\nname = "a"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n'
        '[[boxes]]\nname = "b"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n'
        '[[boxes]]\nname = "c"\nmin = [0, 0, 0]\nmax = [1, 1]\n',
        "boxes[2].max: expected 3 numbers, got 2",
    ),
    (ROOM + '[[boxes]]\nname = "a"\nmin = [0, 0, 1]\nmax = [1, 1, 0.5]\n', "boxes[0].max[2]"),
    (ROOM + '[[boxes]]\nname = "a"\nmin = [0, 0, "x"]\nmax = [1, 1, 1]\n', "boxes[0].min[2]"),
    (ROOM + "[[boxes]]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n", "boxes[0].name: missing"),
    (ROOM + '[[boxes]]\nname = "a"\nmin = [10, 10, 0]\nmax = [11, 11, 1]\n', "outside the room"),
    (ROOM + "colour = 3\n", "colour: unknown field"),
    ('[room]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nname = "t"\n', "room.name: unknown field"),
    ('name = "t"\n', "room: missing"),
    (
        ROOM + '[[floor]]\nname = "f"\nmaterial = "lava"\nmin = [0, 0]\nmax = [1, 1]\n',
        "floor[0].material: expected one of hard, carpet",
    ),
    (
        ROOM + '[[sources]]\nname = "s"\nposition = [0, 0, 0]\nstrength_cps = -5\n',
        "sources[0].strength_cps: expected a number > 0",
    ),
    ("start_positions = [[9.0, 0.0]]\n" + ROOM, "start_positions[0]: outside the room"),
    (
        "start_positions = [[0.0, 0.0, 0.5]]\n"
        + ROOM
        + '[[boxes]]\nname = "a"\nmin = [-1, -1, 0]\nmax = [1, 1, 1]\n',
        "start_positions[0]: inside box 'a'",
    ),
    (
        "start_positions = [[0.0, 0.0, 0.0, 1.0]]\n" + ROOM,
        "start_positions[0]: expected [x, y] or [x, y, z_up], got 4 numbers",
    ),
    (ROOM + "[sensors.imu]\nacc_noise = 0.1\n", "sensors.imu.acc_noise: unknown field"),
    (ROOM + "[sensors.sonar]\nmax_m = -1.0\n", "sensors.sonar.max_m: expected a number > 0"),
    (ROOM + "[sensors.lidar]\nrange_m = 3.0\n", "sensors.lidar: unknown field"),
    (ROOM + "[vehicle]\nmass_kg = 0.1\n", "vehicle.motor_mass_kg"),
    (ROOM + "[mocap]\nenabled = 1\n", "mocap.enabled: expected true or false"),
    (ROOM + "[radiation]\nbackground_cps = -1\n", "radiation.background_cps"),
    (ROOM + "[autopilot]\ngps = 1\n", "autopilot.gps: expected true or false, got 1"),
    (ROOM + '[autopilot]\nrc_input = "none"\n',
     "autopilot.rc_input: expected one of absent, min, mid, got 'none'"),
    (ROOM + "[autopilot]\nhome_distance_m = -2\n", "autopilot.home_distance_m"),
    ("name = [unclosed\n", "not valid TOML"),
]


@pytest.mark.parametrize(("text", "expected"), BAD)
def test_bad_world_errors_name_file_and_field(tmp_path: Path, text: str, expected: str) -> None:
    assert expected in error_of(tmp_path, text)


def test_exact_message_for_a_short_corner(tmp_path: Path) -> None:
    msg = error_of(tmp_path, BAD[0][0])
    assert msg == "boxes[2].max: expected 3 numbers, got 2"


def test_missing_and_binary_files(tmp_path: Path) -> None:
    with pytest.raises(WorldError, match="no such world file"):
        load_world(tmp_path / "nope.toml")
    p = tmp_path / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(WorldError, match="not UTF-8"):
        load_world(p)
    with pytest.raises(WorldError, match="cannot read"):
        load_world(tmp_path)  # a directory
