"""The station's configuration as the vehicle's dialect adjusts it."""

from __future__ import annotations

import dataclasses

from firmware_link.records import Dialect
from gcs.config import ANALOG_SONAR_STEP_M, StationConfig, for_dialect


def test_a_3_2_1_rangefinder_is_judged_at_its_6_cm_steps() -> None:
    base = StationConfig()
    apm = for_dialect(base, Dialect.APM25).estimator
    assert apm.sonar_resolution_m == ANALOG_SONAR_STEP_M
    assert apm.sonar_stale_move_m > ANALOG_SONAR_STEP_M
    assert for_dialect(base, Dialect.COPTER4) == base  # whole centimetres


def test_a_resolution_the_file_chose_stands() -> None:
    base = StationConfig()
    chosen = dataclasses.replace(base, estimator=dataclasses.replace(
        base.estimator, sonar_resolution_m=0.02))
    assert for_dialect(chosen, Dialect.APM25) == chosen
