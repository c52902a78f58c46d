"""docs/log-check.md's table is the thresholds table: every check, its unit, limits and why."""

from __future__ import annotations

from pathlib import Path

from logs.check.thresholds import DEFAULTS

DOC = Path(__file__).resolve().parents[2] / "docs" / "log-check.md"


def test_the_documented_table_is_the_one_the_checks_use() -> None:
    rows = [line for line in DOC.read_text(encoding="utf-8").splitlines()
            if line.startswith("| `")]
    expected = [f"| `{t.key}` | {t.unit} | {t.warn:g} | {t.fail:g} | {t.worse} | {t.why} |"
                for t in DEFAULTS]
    assert rows == expected
