"""Bad input to `mission run` ends in exit 2 with one line naming the problem."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.cli import main

WORLDS = Path(__file__).resolve().parents[2] / "worlds"

GOOD = f"""\
name = "t"
world = "{WORLDS / 'table_room.toml'}"

[planner]
kind = "epbha"
step_m = 0.1

[goal]
position = [2.0, 0.0, 0.45]
"""


def run(tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, *extra: str
        ) -> tuple[int, str]:
    f = tmp_path / "m.toml"
    f.write_text(text)
    code = main(["mission", "run", str(f), "--kinematic", "--no-record", "-q", *extra])
    err = capsys.readouterr().err
    return code, err


def one_line(err: str) -> str:
    assert err.endswith("\n") and err.count("\n") == 1, err
    return err


@pytest.mark.parametrize(("text", "needle"), [
    (GOOD.replace('"epbha"', '"astar"'), "planner.kind: expected one of epbha"),
    (GOOD.replace("step_m = 0.1", "stepsize = 0.1"), "planner.stepsize: unknown parameter"),
    (GOOD.replace("step_m = 0.1", "step_m = 0.4"), "must be below the sensor range"),
    (GOOD.replace("step_m = 0.1", 'step_m = "big"'), "planner.step_m: expected float"),
    (GOOD.replace("table_room.toml", "nowhere.toml"), "world: world file"),
    ("\n".join(GOOD.splitlines()[0:1] + GOOD.splitlines()[2:]), "world: missing"),
    (GOOD.replace("[2.0, 0.0, 0.45]", "[2.0, 0.0]"), "goal.position: expected [x, y, alt]"),
    ("kind = [", "not valid TOML"),
])
def test_bad_mission_files(tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str,
                           needle: str) -> None:
    code, err = run(tmp_path, capsys, text)
    assert code == 2
    assert needle in one_line(err)
    assert err.startswith("quadgcs mission: ")


def test_bad_world_file_names_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    world = tmp_path / "w.toml"
    world.write_text("[room]\nmin = [0, 0]\nmax = [1, 1, 1]\n")
    code, err = run(tmp_path, capsys, GOOD.replace(str(WORLDS / "table_room.toml"), str(world)))
    assert code == 2
    assert f"{world}: room.min: expected 3 numbers" in one_line(err)


def test_missing_file_and_bad_flags(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mission", "run", str(tmp_path / "none.toml"), "--kinematic"]) == 2
    assert "no such mission file" in one_line(capsys.readouterr().err)
    code, err = run(tmp_path, capsys, GOOD, "--connect", "tcp:127.0.0.1:5760")
    assert code == 2 and "--kinematic flies no vehicle" in one_line(err)
    code, err = run(tmp_path, capsys, GOOD, "--speedup", "0")
    assert code == 2 and "--speedup 0" in one_line(err)
    with pytest.raises(SystemExit) as exc:
        main(["mission", "run", "--no-such-flag", "x.toml"])
    assert exc.value.code == 2
    assert "unrecognized arguments: --no-such-flag" in capsys.readouterr().err
    assert main(["mission"]) == 2
    assert "expected an action" in one_line(capsys.readouterr().err)


def test_unwritable_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    f = tmp_path / "m.toml"
    f.write_text(GOOD)
    code = main(["mission", "run", str(f), "--kinematic", "-q", "-o", str(blocker / "sub")])
    assert code == 2
    assert "-o " in one_line(capsys.readouterr().err)
