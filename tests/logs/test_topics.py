"""The topic names logs/ reads are the ones the station writes (gcs/topics.py)."""

from __future__ import annotations

from gcs import topics as theirs
from logs import topics as ours


def test_station_topic_names_match() -> None:
    assert ours.ESTIMATE_TOPIC == theirs.ESTIMATE
    assert ours.ALT_CONTROLLER_TOPIC == theirs.ALT_CONTROLLER
    assert ours.RC_OVERRIDE_TOPIC == theirs.RC_OVERRIDE
    assert ours.EVENTS_TOPIC == theirs.EVENTS
    assert ours.LINK_EVENTS_TOPIC == theirs.LINK_EVENT
    assert ours.RANGEFINDER_TOPIC == theirs.RANGEFINDER
    assert ours.SIM_TRUTH_TOPIC == theirs.SIM_TRUTH
    assert ours.IMU_TOPIC == theirs.IMU
    assert ours.HEARTBEAT_TOPIC == theirs.HEARTBEAT
