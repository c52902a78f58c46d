"""One campaign run without Ray: a row from a flight, and a link fade as a failed row."""

from __future__ import annotations

from pathlib import Path

from gcs.campaign.run import fly_run, make_run
from gcs.campaign.spec import BaseFlight


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
