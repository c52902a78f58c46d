"""Stream planning against the link's byte budget, and the thesis's bring-up steps."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from firmware_link import DataStream, LinkError, StreamWanted, plan_streams, wanted_streams
from firmware_link.protocol import WireVersion, frame_overhead_bytes, payload_bytes
from firmware_link.records import Dialect
from firmware_link.streams import (
    bring_up_periods_ms,
    fast_rate_limit_hz,
    measured_rate_hz,
    step_plan,
)

SERIAL_115200 = 11520.0


def test_frame_overheads_match_the_wire_formats() -> None:
    assert frame_overhead_bytes(WireVersion.V1) == 8
    assert frame_overhead_bytes(WireVersion.V2) == 12
    assert frame_overhead_bytes(WireVersion.V2, signed=True) == 25
    assert payload_bytes("ATTITUDE") == 28
    assert payload_bytes("RC_CHANNELS_OVERRIDE", WireVersion.V1) == 18


@pytest.mark.parametrize(
    ("dialect", "wire", "signed", "grouped"),
    [
        (Dialect.APM25, WireVersion.V1, False, True),
        (Dialect.COPTER4, WireVersion.V2, False, False),
        (Dialect.COPTER4, WireVersion.V2, True, False),
    ],
)
def test_default_plans_fit_115200_baud_with_fast_streams_at_40_hz(
    dialect, wire, signed, grouped
) -> None:
    plan = plan_streams(
        SERIAL_115200, wanted_streams(dialect), wire=wire, signed=signed, grouped=grouped
    )
    assert plan.total_bytes_per_s <= 0.8 * SERIAL_115200 + 1e-6
    assert plan.utilisation_pct is not None and plan.utilisation_pct <= 80.0 + 1e-6
    assert plan.rate_of("ATTITUDE") == 40.0
    assert plan.rate_of("RAW_IMU") == 40.0
    sonar = "RANGEFINDER" if dialect is Dialect.APM25 else "DISTANCE_SENSOR"
    assert plan.rate_of(sonar) == 40.0
    for r in plan.rates:
        assert r.bytes_per_s == pytest.approx(r.frame_bytes * r.rate_hz)
        overhead = frame_overhead_bytes(wire, signed)
        assert r.frame_bytes == payload_bytes(r.message, wire) + overhead
    assert "of 11520 B/s" in plan.budget_lines()[-1]


def test_a_squeezed_link_keeps_priorities_and_trims_the_tail() -> None:
    wanted = [
        StreamWanted("ATTITUDE", 40.0, 10.0, DataStream.EXTRA1),
        StreamWanted("VFR_HUD", 40.0, 2.0, DataStream.EXTRA2),
    ]
    # ATTITUDE costs 40 B/frame on v2, VFR_HUD 32: a 2400 B/s budget fits ATTITUDE at 40 Hz
    # (1600 B/s) and leaves VFR_HUD the rest: its 2 Hz floor plus what remains.
    plan = plan_streams(3000.0, wanted, max_utilisation=0.8)
    assert plan.rate_of("ATTITUDE") == 40.0
    assert plan.rate_of("VFR_HUD") == pytest.approx((2400.0 - 1600.0) / 32.0)
    assert plan.total_bytes_per_s == pytest.approx(2400.0)


def test_grouped_plan_moves_a_group_together_in_whole_hz() -> None:
    wanted = [
        StreamWanted("ATTITUDE", 40.0, 10.0, DataStream.EXTRA1),
        StreamWanted("SIMSTATE", 5.0, 1.0, DataStream.EXTRA1),
        StreamWanted("VFR_HUD", 40.0, 2.0, DataStream.EXTRA2),
    ]
    plan = plan_streams(5000.0, wanted, wire=WireVersion.V1, grouped=True)
    assert plan.rate_of("SIMSTATE") == plan.rate_of("ATTITUDE") == 40.0
    assert plan.rate_of("VFR_HUD") == int(plan.rate_of("VFR_HUD"))
    assert plan.rate_of("VFR_HUD") == 17.0  # (4000 - 88 * 40) / 28 rounded down
    assert plan.total_bytes_per_s <= 4000.0
    assert plan.group_rates()[DataStream.EXTRA1] == 40.0


def test_minimum_rates_that_cannot_fit_are_refused() -> None:
    wanted = [StreamWanted("ATTITUDE", 40.0, 40.0, DataStream.EXTRA1)]
    with pytest.raises(LinkError, match="telemetry minimum needs 1600 B/s"):
        plan_streams(960.0, wanted)


def test_unlimited_link_gets_every_wanted_rate() -> None:
    plan = plan_streams(None, wanted_streams(Dialect.COPTER4), signed=True)
    assert plan.utilisation_pct is None
    assert plan.rate_of("SIM_STATE") == 10.0
    assert "no capacity limit" in plan.budget_lines()[-1]


def test_bring_up_steps_go_from_100_ms_to_25_ms_in_five_steps() -> None:
    periods = bring_up_periods_ms()
    assert periods == (100.0, 85.0, 70.0, 55.0, 40.0, 25.0)
    plan = plan_streams(None, wanted_streams(Dialect.APM25), wire=WireVersion.V1, grouped=True)
    first = step_plan(plan, periods[0], whole_hz=True)
    last = step_plan(plan, periods[-1], whole_hz=True)
    assert first["ATTITUDE"] == 10.0 and last["ATTITUDE"] == 40.0
    assert first["SYS_STATUS"] == last["SYS_STATUS"] == 2.0
    assert step_plan(plan, 85.0, whole_hz=False)["ATTITUDE"] == pytest.approx(1000 / 85)


def test_measured_rate_uses_intervals_over_their_span() -> None:
    stamps = [0.1 + k * 0.025 for k in range(41)]
    assert measured_rate_hz(stamps, 1.0) == pytest.approx(40.0)
    assert measured_rate_hz([], 1.0) == 0.0


def test_measured_budget_limits_the_fast_rate_to_what_fits() -> None:
    # At 25 Hz the link carried 10,000 B/s of which 7,500 B/s ran at the step rate (300 B per
    # cycle); the other 2,500 B/s stay. A 9,216 B/s budget then allows (9216 - 2500) / 300 Hz.
    assert fast_rate_limit_hz(10_000.0, 7_500.0, 25.0, 9_216.0) == pytest.approx(22.387, 1e-3)
    assert fast_rate_limit_hz(1_000.0, 0.0, 25.0, 9_216.0) == float("inf")
    plan = plan_streams(None, wanted_streams(Dialect.APM25), wire=WireVersion.V1, grouped=True)
    limited = step_plan(plan, 25.0, whole_hz=True, limit_hz=33.7)
    assert limited["ATTITUDE"] == 33.0 and limited["VFR_HUD"] == 10.0


MESSAGES = ("ATTITUDE", "RAW_IMU", "RANGEFINDER", "VFR_HUD", "SYS_STATUS", "SERVO_OUTPUT_RAW")


@settings(max_examples=150, deadline=None)
@given(
    capacity=st.floats(min_value=200.0, max_value=50_000.0),
    picks=st.lists(
        st.tuples(
            st.sampled_from(MESSAGES),
            st.floats(min_value=0.5, max_value=50.0),
            st.floats(min_value=0.0, max_value=1.0),
            st.sampled_from(list(DataStream)),
        ),
        min_size=1,
        max_size=6,
        unique_by=lambda t: t[0],
    ),
    grouped=st.booleans(),
)
def test_a_plan_never_exceeds_its_budget_nor_leaves_min_max(capacity, picks, grouped) -> None:
    wanted = [StreamWanted(m, rate, rate * frac, group) for m, rate, frac, group in picks]
    try:
        plan = plan_streams(capacity, wanted, grouped=grouped, wire=WireVersion.V1)
    except LinkError:
        return  # the minimum rates did not fit: refused, as it should be
    assert plan.total_bytes_per_s <= 0.8 * capacity * (1 + 1e-9)
    for w in wanted:
        rate = plan.rate_of(w.message)
        members = [x for x in wanted if (x.group == w.group if grouped else x is w)]
        group_min = max(x.min_rate_hz for x in members)
        group_max = max(x.rate_hz for x in members)
        assert group_min - 1e-9 <= rate <= group_max + 1e-9


def test_apm25_delivers_50_over_n_hz() -> None:
    from firmware_link.streams import BringUpStep, apm25_delivered_hz

    assert apm25_delivered_hz(25) == (50 / 3, 25.0)  # 16.4 Hz measured on the real 3.2.1
    assert apm25_delivered_hz(40) == (25.0, 50.0)  # never 40
    assert apm25_delivered_hz(10) == (50 / 6, 10.0)
    assert apm25_delivered_hz(80) == (25.0, 50.0)  # capped at the 50 Hz loop
    assert apm25_delivered_hz(0.5) == (0.0, 0.0)  # a uint8 rate of 0: off
    step = BringUpStep(25.0, 40.0, 25.1, expected_hz=apm25_delivered_hz(40))
    assert step.delivered() and not BringUpStep(25.0, 40.0, 25.1).delivered()
