"""The pre-flight's verdict and `--fix-failsafe` against a parameter store that behaves like a
vehicle's: it stores what it accepts, refuses what it does not, and is read back."""

from __future__ import annotations

import pytest

from firmware_link.records import Dialect
from gcs.failsafe_policy import VehicleState
from gcs.preflight import evaluate, read_and_check, required_parameters

COMMON = {"RC3_MIN": 1000.0, "RC3_MAX": 2000.0, "RC3_TRIM": 1500.0, "RCMAP_ROLL": 1.0,
          "RCMAP_PITCH": 2.0, "RCMAP_THROTTLE": 3.0, "RCMAP_YAW": 4.0}
COPTER4 = {**COMMON, "FS_GCS_ENABLE": 0.0, "FS_GCS_TIMEOUT": 5.0, "FS_OPTIONS": 16.0,
           "RC_OVERRIDE_TIME": 3.0, "FS_THR_ENABLE": 1.0, "RC_FS_TIMEOUT": 1.0,
           "RTL_ALT": 1500.0, "BATT_LOW_VOLT": 0.0}
APM25 = {**COMMON, "FS_GCS_ENABLE": 1.0, "FS_THR_ENABLE": 1.0, "RTL_ALT": 1500.0,
         "RTL_ALT_FINAL": 0.0, "FS_BATT_VOLTAGE": 10.5}
NO_GPS, GPS = VehicleState(1), VehicleState(3)


class Vehicle:
    """Parameters as the vehicle holds them; `refuse` names parameters it will not store."""

    def __init__(self, params: dict[str, float], refuse: tuple[str, ...] = ()) -> None:
        self.params = dict(params)
        self.refuse = refuse
        self.sets: list[tuple[str, float]] = []
        self.reads: list[str] = []

    def get(self, name: str) -> float:
        self.reads.append(name)
        if name not in self.params:
            raise KeyError(f"no value for {name} within 3.0 s")
        return self.params[name]

    def set(self, name: str, value: float) -> float:
        self.sets.append((name, value))
        if name in self.refuse:
            raise ValueError(f"{name} stored {self.params[name]:g}")
        self.params[name] = value
        return value


def test_the_parameters_read_are_the_ones_judged() -> None:
    for dialect, params in ((Dialect.COPTER4, COPTER4), (Dialect.APM25, APM25)):
        assert set(required_parameters(dialect)) == set(params)


def test_4x_defaults_are_refused_with_one_line_naming_the_parameter() -> None:
    report = evaluate(Dialect.COPTER4, COPTER4, 12.4, state=NO_GPS)
    assert not report.ok
    assert report.summary() == ("FS_GCS_ENABLE 0: on a silent link the vehicle keeps flying on "
                                "the receiver's throttle (no GCS failsafe); set FS_GCS_ENABLE 5 "
                                "or pass --fix-failsafe")
    assert report.fixes == {"FS_OPTIONS": 0.0, "FS_GCS_ENABLE": 5.0, "FS_GCS_TIMEOUT": 2.0}


def test_4x_with_only_the_gcs_failsafe_on_is_refused_for_fs_options() -> None:
    params = {**COPTER4, "FS_GCS_ENABLE": 5.0, "FS_GCS_TIMEOUT": 2.0}
    report = evaluate(Dialect.COPTER4, params, 12.4, state=NO_GPS)
    assert report.summary().startswith("FS_OPTIONS 16: on a silent link the vehicle keeps "
                                       "flying on the receiver's throttle")


def test_fix_failsafe_sets_reads_back_and_says_it_in_one_line() -> None:
    v = Vehicle(COPTER4)
    report = read_and_check(v.get, v.set, Dialect.COPTER4, 12.4, fix=True, state=NO_GPS)
    assert report.ok, report.summary()
    assert sorted(v.sets) == [("FS_GCS_ENABLE", 5.0), ("FS_GCS_TIMEOUT", 2.0),
                              ("FS_OPTIONS", 0.0)]
    # every parameter read again after the sets
    assert v.reads.count("FS_OPTIONS") == 2 and v.reads.count("RC3_MIN") == 2
    line = report.fix_line()
    assert line == ("--fix-failsafe: set FS_GCS_ENABLE 0 -> 5, FS_GCS_TIMEOUT 5 -> 2, "
                    "FS_OPTIONS 16 -> 0 (read back); FS_GCS_ENABLE 5: on a silent link the "
                    "vehicle after 2 s holds 4 s, then lands")


def test_without_consent_nothing_is_set() -> None:
    v = Vehicle(COPTER4)
    report = read_and_check(v.get, v.set, Dialect.COPTER4, 12.4, fix=False, state=NO_GPS)
    assert not report.ok and v.sets == [] and report.fix_line() is None


def test_a_set_the_vehicle_refuses_still_refuses_the_flight() -> None:
    v = Vehicle(COPTER4, refuse=("FS_OPTIONS",))
    report = read_and_check(v.get, v.set, Dialect.COPTER4, 12.4, fix=True, state=NO_GPS)
    assert not report.ok
    assert report.summary().startswith("FS_OPTIONS 16: on a silent link the vehicle keeps")
    assert report.summary().endswith("--fix-failsafe: FS_OPTIONS not set to 0 (FS_OPTIONS "
                                     "stored 16)")
    assert (report.fix_line() or "").startswith(
        "--fix-failsafe: set FS_GCS_ENABLE 0 -> 5, FS_GCS_TIMEOUT 5 -> 2 (read back); "
        "FS_OPTIONS not set to 0 (FS_OPTIONS stored 16); FS_OPTIONS 16: ")


def test_a_value_that_reads_back_different_is_judged_as_read() -> None:
    v = Vehicle(COPTER4)
    real_set = v.set

    def set_but_keep_bit_4(name: str, value: float) -> float:
        real_set(name, value)
        if name == "FS_OPTIONS":
            v.params[name] = 16.0  # the vehicle said yes, but a read shows otherwise
        return value

    report = read_and_check(v.get, set_but_keep_bit_4, Dialect.COPTER4, 12.4, fix=True,
                            state=NO_GPS)
    assert not report.ok and report.summary().startswith("FS_OPTIONS 16:")


def test_3_2_1_with_gps_gets_rtl_alt_0_and_without_gps_is_left_alone() -> None:
    v = Vehicle(APM25)
    report = read_and_check(v.get, v.set, Dialect.APM25, 12.4, fix=True, state=GPS)
    assert report.ok and v.sets == [("RTL_ALT", 0.0)]
    assert report.fix_line() == ("--fix-failsafe: set RTL_ALT 1500 -> 0 (read back); RTL_ALT 0: "
                                 "on a silent link the vehicle after 5 s returns home at its "
                                 "height in RTL (RTL_ALT 0), loiters, then lands (GPS 3D fix)")
    v = Vehicle(APM25)
    report = read_and_check(v.get, v.set, Dialect.APM25, 12.4, fix=True, state=NO_GPS)
    assert report.ok and v.sets == []


def test_gps_not_reported_is_judged_as_a_fix() -> None:
    report = evaluate(Dialect.APM25, APM25, 12.4, state=None)
    assert not report.ok
    assert "GPS not reported" in report.summary()


@pytest.mark.parametrize("missing", ["FS_OPTIONS", "RC_OVERRIDE_TIME", "RTL_ALT"])
def test_an_unreadable_failsafe_parameter_refuses_by_name(missing: str) -> None:
    params = {k: v for k, v in COPTER4.items() if k != missing}
    v = Vehicle(params)
    report = read_and_check(v.get, v.set, Dialect.COPTER4, 12.4, fix=True, state=NO_GPS)
    assert not report.ok
    assert f"could not read {missing}" in report.summary()
