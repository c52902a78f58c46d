"""One campaign run without Ray: a row from a flight, and a link fade as a failed row."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from lab.campaign.results import mission_summary_table
from lab.campaign.run import RunSpec, fly_run, make_run
from lab.campaign.types import BaseFlight
from sitl import native


def test_a_downlink_fade_in_the_hold_is_a_failed_row_naming_the_lost_link(tmp_path: Path
                                                                          ) -> None:
    base = BaseFlight(hold_s=6.0)
    clean = fly_run(base, make_run(base, {"seed": 2}), tmp_path, "t")
    assert clean["status"] == "ok" and clean["link_down_s"] == 0.0
    # holding from about 15 s: a 5 s fade of everything the vehicle sends, from 17 s
    fade = {"seed": 2, "link.fade": "down", "link.fade_start_s": 17.0, "link.fade_s": 5.0}
    row = fly_run(base, make_run(base, fade), tmp_path, "t")
    assert row["status"] == "failed" and row["link.fade"] == "down"
    assert "nothing heard from the vehicle for 1.5 s" in row["reason"]
    assert row["cpu_s"] > 0.0 and row["worker"]
    assert row["sitl"] == native.build_kind() and row["sitl"] in ("compiled", "interpreted")


class _Ref:
    def __init__(self, value: dict) -> None:
        self.value = value


class InterruptedRay:
    """Ray's calls as the driver uses them; the pilot presses Ctrl-C after `finish` rows."""

    def __init__(self, finish: int) -> None:
        self.finish = finish
        self.cancelled = 0

    def remote(self, **_: object) -> Callable[[object], type]:
        class Task:
            @staticmethod
            def remote(*args: object) -> _Ref:
                return _Ref(_row(args[1]))  # (base, run, output, campaign)
        return lambda fn: Task

    def wait(self, refs: list, num_returns: int, timeout: float) -> tuple[list, list]:
        if self.finish == 0:
            raise KeyboardInterrupt
        self.finish -= 1
        return refs[:1], refs[1:]

    def get(self, ref: _Ref) -> dict:
        return ref.value

    def cancel(self, ref: _Ref, force: bool) -> None:
        self.cancelled += 1


def _row(run: object) -> dict:
    from lab.campaign.metrics import flown_row

    assert isinstance(run, RunSpec)
    return flown_row(run.run_id, run.values, {"rms_error_m": 0.01, "error_source": "truth"})


def test_ctrl_c_keeps_the_finished_rows_and_a_rerun_flies_the_rest(tmp_path: Path) -> None:
    from lab.campaign import load_campaign, read_results, run_campaign

    path = tmp_path / "c.toml"
    path.write_text("[axes]\nseed = { range = [1, 5] }\n", encoding="utf-8")
    c = load_campaign(path)
    ray = InterruptedRay(finish=2)
    first = run_campaign(c, tmp_path / "out", ray, quiet=True)
    assert not first.complete and first.ran == 2 and ray.cancelled == 3
    assert [r["seed"] for r in read_results(first.results)] == [1, 2]
    second = run_campaign(c, tmp_path / "out", InterruptedRay(finish=10), quiet=True)
    assert second.complete and (second.ran, second.skipped) == (3, 2)
    assert sorted(r["seed"] for r in read_results(second.results)) == [1, 2, 3, 4, 5]


def test_a_mapping_missions_summary_gives_its_iou_median_and_worst() -> None:
    rows = [{"seed": s, "status": "ok", "iou": iou, "collisions": 0.0, "mission_s": 250.0}
            for s, iou in ((1, 0.96), (2, 0.94), (3, 0.98))]
    rows.append({"seed": 4, "status": "failed", "iou": None, "mission_s": 30.0})  # never scored
    head, line = mission_summary_table(rows, ["seed"]).splitlines()
    assert head.split()[-3:] == ["IoU", "median", "worst"]
    assert line.split()[:3] == ["4", "3", "1"] and line.split()[-2:] == ["0.96", "0.94"]
