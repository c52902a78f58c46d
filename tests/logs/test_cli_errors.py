"""Bad input of every kind ends in one line naming the file and the problem, exit 2."""

from __future__ import annotations

import pytest
from mcap.writer import Writer

from gcs.cli import main


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "Traceback" not in err[0]
    return err[0]


@pytest.fixture
def truncated(recorded_flight, tmp_path):
    path, _ = recorded_flight
    broken = tmp_path / "broken.mcap"
    broken.write_bytes(path.read_bytes()[:-4000])
    return broken


@pytest.fixture
def cdr_file(tmp_path):
    path = tmp_path / "cdr.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        sid = w.register_schema("pkg/Msg", "ros2msg", b"int32 a")
        cid = w.register_channel("/cdr", "cdr", sid)
        w.add_message(cid, 1, b"\x00\x01\x00\x00\x01\x00\x00\x00", 1)
        w.finish()
    return path


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["logs", "info", "{missing}"], "no such file"),
        (["logs", "info", "{text}"], "not an MCAP file"),
        (["logs", "info", "{truncated}"], "truncated: recover it with quadgcs logs recover"),
        (["logs", "export", "{truncated}", "--tlog", "{out}"], "truncated: recover it"),
        (["replay", "{truncated}", "--max"], "truncated: recover it"),
        (["logs", "export", "{good}"], "give --tlog OUT and/or --csv DIR"),
        (["logs", "export", "{good}", "--tlog", "{blocked}/x.tlog"], "cannot write"),
        (["logs", "export", "{good}", "--csv", "{blocked}/dir"], "cannot create directory"),
        (["logs", "export", "{good}", "--csv", "{out}", "--topic", "/nope"], "no topic /nope"),
        (["logs", "export", "{cdr}", "--csv", "{out}"], "expected JSON"),
        (["logs", "plot", "{missing}"], "no such file"),
        (["logs", "recover", "{text}"], "not an MCAP file"),
        (["logs", "recover", "{truncated}", "-o", "{blocked}/x.mcap"], "cannot write"),
        (["logs", "import-tlog", "{text}", "-o", "{out}"], "not a tlog"),
        (["logs", "import-tlog", "{missing}", "-o", "{out}"], "no such file"),
        (["replay", "{good}", "--speed", "-1"], "speed must be a positive number"),
    ],
)
def test_bad_input_exits_2_with_one_line(
    argv, needle, recorded_flight, truncated, cdr_file, tmp_path, capsys
) -> None:
    good, _ = recorded_flight
    text = tmp_path / "notes.txt"
    text.write_text("this is not a flight recording\n" * 10)
    blocked = tmp_path / "blocked"
    blocked.write_text("a file where a directory should be")
    names = {
        "missing": tmp_path / "nope.mcap",
        "text": text,
        "truncated": truncated,
        "good": good,
        "cdr": cdr_file,
        "out": tmp_path / "out",
        "blocked": blocked,
    }
    args = [a.format(**names) for a in argv]
    assert main(args) == 2
    line = _one_error_line(capsys)
    assert needle in line
    assert line.startswith(f"quadgcs {args[0]}: ")


def test_logs_without_action_prints_help(capsys) -> None:
    assert main(["logs"]) == 2
    assert "info" in capsys.readouterr().err
