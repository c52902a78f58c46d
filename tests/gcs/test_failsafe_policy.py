"""The failsafe prediction: parameters + vehicle state → what a silent link ends in.

Rows follow the real firmware's measured behaviour (fixtures/README.md, "What the real firmware
does when the station goes silent") and its failsafe code; a grid runs every combination of the
parameters that decide it and checks that `--fix-failsafe`'s settings always make it safe.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping

import pytest

from firmware_link.parm_file import read_parm_file
from firmware_link.records import Dialect, FlightMode
from gcs.failsafe_policy import (
    FLOWN_MODES,
    Outcome,
    VehicleState,
    predict,
    required_parameters,
    safe_settings,
)
from tests.fixture_paths import FIXTURES

C4, APM = Dialect.COPTER4, Dialect.APM25
# the real firmware's defaults (fixtures' parameter lists)
C4_DEFAULTS = {"FS_GCS_ENABLE": 0.0, "FS_GCS_TIMEOUT": 5.0, "FS_OPTIONS": 16.0,
               "RC_OVERRIDE_TIME": 3.0, "FS_THR_ENABLE": 1.0, "RC_FS_TIMEOUT": 1.0,
               "RTL_ALT": 1500.0}
APM_DEFAULTS = {"FS_GCS_ENABLE": 1.0, "FS_THR_ENABLE": 1.0, "RTL_ALT": 1500.0,
                "RTL_ALT_FINAL": 0.0}
NO_GPS, GPS, UNKNOWN = VehicleState(1), VehicleState(3), VehicleState(None)
NO_RX_NO_GPS = VehicleState(1, receiver=False)
NO_RX_GPS = VehicleState(3, receiver=False)
# what `quadgcs fly --fix-failsafe` set on 4.7 for the fixture flights, and with FS_OPTIONS off
C4_FIXED = {**C4_DEFAULTS, "FS_GCS_ENABLE": 5.0, "FS_GCS_TIMEOUT": 2.0}
C4_SAFE = {**C4_FIXED, "FS_OPTIONS": 0.0}


def _p(base: Mapping[str, float], **kw: float) -> dict[str, float]:
    return {**base, **kw}


ROWS = [
    # dialect, params, state, outcome, deciding parameter, words in the line
    # -- 4.x: FS_OPTIONS bit 4 and the override lapse (measured: floor at 3.5-4.4 m/s)
    (C4, C4_DEFAULTS, NO_GPS, Outcome.KEEPS_FLYING, "FS_GCS_ENABLE", "receiver's throttle"),
    (C4, C4_FIXED, NO_GPS, Outcome.KEEPS_FLYING, "FS_OPTIONS", "receiver's throttle"),
    (C4, C4_FIXED, GPS, Outcome.KEEPS_FLYING, "FS_OPTIONS", "bit 4"),
    (C4, _p(C4_FIXED, FS_OPTIONS=18.0), NO_GPS, Outcome.KEEPS_FLYING, "FS_OPTIONS", "bit 4"),
    (C4, _p(C4_FIXED, RC_OVERRIDE_TIME=-1.0), NO_GPS, Outcome.KEEPS_FLYING, "FS_OPTIONS",
     "last override"),
    # no receiver: the last override stays until the radio failsafe
    (C4, C4_FIXED, NO_RX_NO_GPS, Outcome.HOLD_THEN_LAND, "FS_OPTIONS", "radio failsafe"),
    (C4, C4_FIXED, NO_RX_GPS, Outcome.CLIMB, "FS_OPTIONS", "RTL_ALT 15 m"),
    (C4, _p(C4_FIXED, FS_THR_ENABLE=3.0), NO_RX_GPS, Outcome.HOLD_THEN_LAND, "FS_OPTIONS",
     "after 4 s holds 4 s"),
    (C4, _p(C4_FIXED, FS_THR_ENABLE=0.0), NO_RX_NO_GPS, Outcome.KEEPS_FLYING, "FS_OPTIONS",
     "last override"),
    (C4, _p(C4_DEFAULTS, FS_THR_ENABLE=3.0), NO_RX_NO_GPS, Outcome.HOLD_THEN_LAND,
     "FS_GCS_ENABLE", "radio failsafe"),
    # -- 4.x: FS_OPTIONS off (measured: LAND at +2.17 s, touchdown 0.49 m/s)
    (C4, C4_SAFE, NO_GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE", "holds 4 s, then lands"),
    (C4, C4_SAFE, GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE", "after 2 s"),
    (C4, _p(C4_SAFE, FS_OPTIONS=2.0), GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE", "lands"),
    (C4, _p(C4_SAFE, FS_GCS_TIMEOUT=3.0), NO_GPS, Outcome.KEEPS_FLYING, "FS_GCS_TIMEOUT",
     "under RC_OVERRIDE_TIME 3"),
    (C4, _p(C4_SAFE, FS_GCS_TIMEOUT=5.0), GPS, Outcome.KEEPS_FLYING, "FS_GCS_TIMEOUT",
     "before its failsafe at 5 s"),
    (C4, _p(C4_SAFE, FS_GCS_TIMEOUT=5.0, RC_OVERRIDE_TIME=-1.0), NO_GPS,
     Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE", "after 5 s"),
    (C4, _p(C4_SAFE, RC_OVERRIDE_TIME=0.0), NO_GPS, Outcome.UNKNOWN, "RC_OVERRIDE_TIME",
     "ignores the station's sticks"),
    # actions: RTL family climbs or navigates with a position, lands without one
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=1.0), GPS, Outcome.CLIMB, "FS_GCS_ENABLE", "RTL_ALT 15 m"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=1.0), UNKNOWN, Outcome.CLIMB, "FS_GCS_ENABLE",
     "GPS not reported"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=1.0, RTL_ALT=0.0), GPS, Outcome.NAVIGATE, "FS_GCS_ENABLE",
     "flies home"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=1.0), NO_GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE",
     "RTL needs a position"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=2.0), GPS, Outcome.CLIMB, "FS_GCS_ENABLE", "RTL"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=3.0), GPS, Outcome.NAVIGATE, "FS_GCS_ENABLE", "SmartRTL"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=3.0), NO_GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE",
     "SmartRTL needs a position"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=4.0), GPS, Outcome.NAVIGATE, "FS_GCS_ENABLE", "path back"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=4.0), NO_GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE",
     "lands"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=6.0), GPS, Outcome.CLIMB, "FS_GCS_ENABLE", "RTL"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=6.0), NO_GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE",
     "lands"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=7.0), GPS, Outcome.HOLD, "FS_GCS_ENABLE", "never landing"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=7.0), NO_GPS, Outcome.HOLD_THEN_LAND, "FS_GCS_ENABLE",
     "Brake needs a position"),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=9.0), NO_GPS, Outcome.UNKNOWN, "FS_GCS_ENABLE",
     "not one this station knows"),
    # -- 3.2.1 (measured: RTL to 14.0-14.3 m with GPS; lands without)
    (APM, APM_DEFAULTS, GPS, Outcome.CLIMB, "RTL_ALT", "climbs to RTL_ALT 15 m"),
    (APM, APM_DEFAULTS, UNKNOWN, Outcome.CLIMB, "RTL_ALT", "GPS not reported"),
    (APM, APM_DEFAULTS, NO_GPS, Outcome.LAND, "FS_GCS_ENABLE", "after 5 s lands"),
    (APM, _p(APM_DEFAULTS, RTL_ALT=0.0), GPS, Outcome.HOLD_THEN_LAND, "RTL_ALT",
     "returns home at its height"),
    (APM, _p(APM_DEFAULTS, RTL_ALT=0.0, RTL_ALT_FINAL=200.0), GPS, Outcome.HOLD,
     "RTL_ALT_FINAL", "never landing"),
    (APM, _p(APM_DEFAULTS, RTL_ALT_FINAL=200.0), NO_GPS, Outcome.LAND, "FS_GCS_ENABLE",
     "lands"),
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=2.0), GPS, Outcome.CLIMB, "RTL_ALT", "RTL"),
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=0.0), NO_GPS, Outcome.KEEPS_FLYING, "FS_GCS_ENABLE",
     "never lapse"),
    # 3.2.1 with no receiver: the radio failsafe 2 s after the last override
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=0.0), NO_RX_NO_GPS, Outcome.LAND, "FS_GCS_ENABLE",
     "after 2 s lands"),
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=0.0), NO_RX_GPS, Outcome.CLIMB, "RTL_ALT",
     "radio failsafe"),
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=0.0, FS_THR_ENABLE=3.0), NO_RX_GPS, Outcome.LAND,
     "FS_GCS_ENABLE", "FS_THR_ENABLE 3"),
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=0.0, FS_THR_ENABLE=0.0), NO_RX_GPS,
     Outcome.KEEPS_FLYING, "FS_GCS_ENABLE", "last override"),
    (APM, APM_DEFAULTS, NO_RX_GPS, Outcome.CLIMB, "RTL_ALT", "RTL"),
]


@pytest.mark.parametrize(("dialect", "params", "state", "outcome", "param", "words"), ROWS)
@pytest.mark.parametrize("mode", FLOWN_MODES)
def test_prediction_table(dialect: Dialect, params: dict[str, float], state: VehicleState,
                          outcome: Outcome, param: str, words: str, mode: FlightMode) -> None:
    p = predict(dialect, params, state, mode)
    assert (p.outcome, p.param) == (outcome, param), p.line()
    line = p.line()
    assert words in line
    assert "\n" not in line
    assert line.startswith(f"{param} {params[param]:g}: on a silent link the vehicle ")
    assert p.safe == outcome.safe
    if not p.safe:
        assert line.endswith("or pass --fix-failsafe") == p.fixable


def test_the_refusal_line_for_4x_default_fs_options() -> None:
    line = predict(C4, C4_FIXED, NO_GPS).line()
    assert line == ("FS_OPTIONS 16: on a silent link the vehicle keeps flying on the receiver's "
                    "throttle (bit 4: continue in pilot-controlled modes); set bit 4 off or pass "
                    "--fix-failsafe")


def test_the_refusal_line_for_3_2_1_defaults_with_gps() -> None:
    line = predict(APM, APM_DEFAULTS, GPS).line()
    assert line == ("RTL_ALT 1500: on a silent link the vehicle after 5 s climbs to RTL_ALT 15 m "
                    "in RTL (GPS 3D fix); set RTL_ALT 0 (return at the current height) or pass "
                    "--fix-failsafe")


@pytest.mark.parametrize(("dialect", "params", "state", "want"), [
    (C4, C4_DEFAULTS, NO_GPS,
     {"FS_OPTIONS": 0.0, "FS_GCS_ENABLE": 5.0, "FS_GCS_TIMEOUT": 2.0}),
    (C4, _p(C4_DEFAULTS, FS_OPTIONS=23.0, RC_OVERRIDE_TIME=10.0), NO_GPS,
     {"FS_OPTIONS": 7.0, "FS_GCS_ENABLE": 5.0}),
    (C4, _p(C4_DEFAULTS, RC_OVERRIDE_TIME=6.5, FS_GCS_TIMEOUT=8.0), NO_GPS,
     {"FS_OPTIONS": 0.0, "FS_GCS_ENABLE": 5.0, "FS_GCS_TIMEOUT": 2.0}),
    (C4, _p(C4_SAFE, RC_OVERRIDE_TIME=1.5), NO_GPS,
     {"RC_OVERRIDE_TIME": 3.0}),
    (C4, _p(C4_SAFE, RC_OVERRIDE_TIME=0.0, FS_GCS_TIMEOUT=5.0), NO_GPS,
     {"RC_OVERRIDE_TIME": 3.0, "FS_GCS_TIMEOUT": 2.0}),
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=1.0), NO_GPS, {}),  # RTL without a position lands
    (C4, _p(C4_SAFE, FS_GCS_ENABLE=1.0), GPS, {"FS_GCS_ENABLE": 5.0}),
    (C4, C4_SAFE, GPS, {}),
    (APM, APM_DEFAULTS, GPS, {"RTL_ALT": 0.0}),
    (APM, APM_DEFAULTS, NO_GPS, {}),
    (APM, _p(APM_DEFAULTS, FS_GCS_ENABLE=0.0, RTL_ALT_FINAL=100.0), UNKNOWN,
     {"FS_GCS_ENABLE": 1.0, "RTL_ALT": 0.0, "RTL_ALT_FINAL": 0.0}),
])
def test_fix_failsafe_sets(dialect: Dialect, params: dict[str, float], state: VehicleState,
                           want: dict[str, float]) -> None:
    assert safe_settings(dialect, params, state) == want


GRID: dict[Dialect, dict[str, tuple[float, ...]]] = {
    C4: {"FS_GCS_ENABLE": (0, 1, 2, 3, 4, 5, 6, 7, 9), "FS_GCS_TIMEOUT": (2, 3, 5),
         "FS_OPTIONS": (0, 2, 16, 18), "RC_OVERRIDE_TIME": (-1, 0, 1.5, 3, 10),
         "FS_THR_ENABLE": (0, 1, 3, 7), "RC_FS_TIMEOUT": (1,), "RTL_ALT": (0, 1500)},
    APM: {"FS_GCS_ENABLE": (0, 1, 2, 3), "FS_THR_ENABLE": (0, 1, 2, 3),
          "RTL_ALT": (0, 1500), "RTL_ALT_FINAL": (0, 200)},
}
STATES = [VehicleState(g, r) for g in (None, 0, 1, 2, 3, 6) for r in (None, True, False)]


@pytest.mark.parametrize("dialect", [C4, APM])
def test_every_combination_is_judged_and_the_fix_makes_it_safe(dialect: Dialect) -> None:
    names = required_parameters(dialect)
    grid = GRID[dialect]
    assert set(grid) == set(names)
    judged = 0
    for values in itertools.product(*(grid[n] for n in names)):
        params = {n: float(v) for n, v in zip(names, values, strict=True)}
        for state in STATES:
            p = predict(dialect, params, state)
            line = p.line()
            assert line.startswith(f"{p.param} ") and "\n" not in line
            # a landing may never follow a climb, whatever the receiver or GPS
            assert p.safe == (p.outcome in (Outcome.LAND, Outcome.HOLD_THEN_LAND))
            if dialect is C4 and int(params["FS_OPTIONS"]) & 16 and state.receiver is not False:
                assert not p.safe  # bit 4: the receiver's throttle, whatever it is
            if state.position and dialect is APM and params["RTL_ALT"] > 0 \
                    and params["FS_GCS_ENABLE"] != 0:
                assert p.outcome is Outcome.CLIMB
            fixed = {**params, **safe_settings(dialect, params, state)}
            after = predict(dialect, fixed, state)
            assert after.safe, (params, state, after.line())
            assert p.safe or p.fixable, line
            assert p.safe or line.endswith("or pass --fix-failsafe"), line
            judged += 1
    assert judged == len(STATES) * len(list(itertools.product(*grid.values())))


def test_a_missing_parameter_is_named() -> None:
    params = dict(C4_SAFE)
    del params["FS_OPTIONS"]
    p = predict(C4, params, NO_GPS)
    assert (p.outcome, p.param, p.value) == (Outcome.UNKNOWN, "FS_OPTIONS", None)
    assert p.line().startswith("FS_OPTIONS unreadable:")


def test_a_mode_the_station_does_not_fly_is_not_predicted() -> None:
    assert predict(C4, C4_SAFE, NO_GPS, FlightMode.AUTO).outcome is Outcome.UNKNOWN


@pytest.mark.skipif(not FIXTURES.is_dir(), reason=f"no fixtures at {FIXTURES}")
@pytest.mark.parametrize(("name", "dialect", "outcome", "param"), [
    # 4.7 as the fixture flights had it: bit 4 kept it flying; the floor at 3.5-4.4 m/s
    ("arducopter-4.7dev-althold-steps.params.txt", C4, Outcome.KEEPS_FLYING, "FS_OPTIONS"),
    ("arducopter-4.7dev-sitl-params.txt", C4, Outcome.KEEPS_FLYING, "FS_GCS_ENABLE"),
    # 3.2.1's defaults with the simulator's GPS: RTL climbed to 13.6-14.3 m
    ("arducopter-3.2.1-althold-steps.params.txt", APM, Outcome.CLIMB, "RTL_ALT"),
    ("arducopter-3.2.1-sitl-params.txt", APM, Outcome.CLIMB, "RTL_ALT"),
])
def test_the_real_firmwares_parameters(name: str, dialect: Dialect, outcome: Outcome,
                                       param: str) -> None:
    params = read_parm_file(FIXTURES / name)
    p = predict(dialect, params, GPS)  # both simulators had a GPS with home set
    assert (p.outcome, p.param) == (outcome, param), p.line()
    fixed = {**params, **safe_settings(dialect, params, GPS)}
    assert predict(dialect, fixed, GPS).safe


def test_an_override_lapse_too_short_for_any_gcs_timeout() -> None:
    p = predict(C4, _p(C4_SAFE, RC_OVERRIDE_TIME=1.5), NO_GPS)
    assert (p.outcome, p.param) == (Outcome.KEEPS_FLYING, "FS_GCS_TIMEOUT")
    assert p.line().endswith("set RC_OVERRIDE_TIME over FS_GCS_TIMEOUT's least 2 s or pass "
                             "--fix-failsafe")
