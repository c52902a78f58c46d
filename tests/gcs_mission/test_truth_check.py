"""Collision books against ground truth: the airframe's flat cylinder against boxes."""

from __future__ import annotations

import pytest

from gcs.mission.truth_check import BODY_RADIUS_M, body_clearance_m, check_contacts
from planners.geometry import Box

TABLE = Box("table_top", (1.4, -0.4, -0.75), (2.6, 0.4, -0.72))


def test_clearance_beside_above_and_under_a_table_top() -> None:
    # 0.3 m east of the edge at the top's height: the 0.25 m arms leave 5 cm
    assert body_clearance_m((2.0, 0.7, -0.73), TABLE) == pytest.approx(0.05)
    # 0.3 m under the top: the body's 4 cm half height leaves 26 cm
    assert body_clearance_m((2.0, 0.0, -0.42), TABLE) == pytest.approx(0.26)
    # diagonal from the edge: both gaps combine
    assert body_clearance_m((2.0, 0.75, -1.0), TABLE) == pytest.approx(
        ((0.35 - BODY_RADIUS_M) ** 2 + (0.25 - 0.04) ** 2) ** 0.5)
    assert body_clearance_m((2.0, 0.6, -0.73), TABLE) < 0.0


def test_a_contact_counts_once_until_it_ends() -> None:
    track = [(2.0, 1.0, -0.73), (2.0, 0.6, -0.73), (2.0, 0.55, -0.73), (2.0, 1.0, -0.73),
             (2.0, 0.6, -0.73)]
    books = check_contacts(track, [TABLE])
    assert books.collisions == 2
    assert books.touched == ("table_top",)
    assert books.samples == 5 and books.min_clearance_m < 0.0


def test_a_clean_track_has_no_contacts() -> None:
    books = check_contacts([(0.0, 0.0, -1.0), (1.0, 0.0, -1.0)], [TABLE])
    assert books.collisions == 0 and books.touched == ()
    assert books.min_clearance_m == pytest.approx((0.15**2 + 0.21**2) ** 0.5)
