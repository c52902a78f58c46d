"""Recorded records come back as the same records, whatever finite values they carry."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from firmware_link.records import Heartbeat, Imu, LinkEvent, LinkEventKind, SimTruth, SystemStatus
from logs.encoding import encode_json, from_jsonable, to_jsonable

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
vec3 = st.tuples(finite, finite, finite)
text = st.text(max_size=20)


def _round_trip(record):
    import json

    return from_jsonable(type(record), json.loads(encode_json(to_jsonable(record))))


@settings(max_examples=60, deadline=None)
@given(t=finite, acc=vec3, gyro=vec3, source=text, usec=st.integers(0, 2**63 - 1))
def test_imu_round_trips(t, acc, gyro, source, usec) -> None:
    imu = Imu(t, 1, acc, gyro, source, usec)
    assert _round_trip(imu) == imu


@settings(max_examples=40, deadline=None)
@given(mode=st.integers(0, 30), armed=st.booleans(), status=st.sampled_from(list(SystemStatus)))
def test_heartbeat_round_trips_with_enum_members(mode, armed, status) -> None:
    beat = Heartbeat(1.0, 1, 1, mode, armed, status, 81)
    back = _round_trip(beat)
    assert back == beat and back.system_status is status


@settings(max_examples=40, deadline=None)
@given(pos=vec3, kind=st.sampled_from(list(LinkEventKind)), detail=text)
def test_nan_becomes_null_and_comes_back_as_nan(pos, kind, detail) -> None:
    truth = SimTruth(2.0, 1, (pos[0], pos[1], math.nan), pos, 0.0, 0.0, math.inf, "SIMSTATE")
    back = _round_trip(truth)
    assert back.pos_n[:2] == pos[:2] and math.isnan(back.pos_n[2])
    assert math.isnan(back.yaw_rad)  # JSON has no infinity either: it is lost as "not a number"
    event = LinkEvent(3.0, 1, kind, detail)
    assert _round_trip(event) == event
