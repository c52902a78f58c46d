"""The climb-rate hold's pure parts: ALT_HOLD's stick map per firmware and the loop's rates."""

from __future__ import annotations

import pytest

from firmware_link.records import Dialect
from gcs.config import HoldMode, config_from_table
from gcs.control.climb_rate_hold import ClimbRateHold, ClimbRateHoldParams, sqrt_shape
from gcs.control.climb_stick import ClimbStickMap
from gcs.errors import UsageError
from gcs.estimation import AltEstimate, SonarStatus
from sitl.autopilot.pilot_climb import climb_rate_apm25, climb_rate_copter4

FIXTURE_PARAMS = {  # the fixtures' althold-steps parameter lists
    Dialect.COPTER4: {"THR_DZ": 100.0, "RC3_DZ": 30.0, "PILOT_SPEED_UP": 250.0,
                      "PILOT_SPEED_DN": 0.0},
    Dialect.APM25: {"THR_MIN": 130.0, "THR_DZ": 100.0, "RC3_DZ": 30.0, "PILOT_VELZ_MAX": 250.0},
}


@pytest.mark.parametrize("dialect", [Dialect.APM25, Dialect.COPTER4])
def test_stick_map_is_the_firmwares_at_every_microsecond(dialect: Dialect) -> None:
    m = ClimbStickMap.for_dialect(dialect, FIXTURE_PARAMS[dialect])
    for pwm in range(1000, 2001):
        cms = (climb_rate_copter4(pwm, 30, 100, 250.0, 0.0) if dialect is Dialect.COPTER4
               else climb_rate_apm25(pwm, 30, 100, 130, 250))
        assert m.rate_mps(pwm) == pytest.approx(cms / 100.0, abs=1e-12), pwm


@pytest.mark.parametrize(("dialect", "dead_zone"), [(Dialect.COPTER4, (1403, 1597)),
                                                     (Dialect.APM25, (1331, 1554))])
def test_dead_zone_matches_the_fixtures(dialect: Dialect, dead_zone: tuple[int, int]) -> None:
    lo, hi = ClimbStickMap.for_dialect(dialect, FIXTURE_PARAMS[dialect]).dead_zone_us
    assert abs(lo - dead_zone[0]) <= 2 and abs(hi - dead_zone[1]) <= 2


@pytest.mark.parametrize("dialect", [Dialect.APM25, Dialect.COPTER4])
def test_inverse_gives_the_nearest_rate_and_mid_stick_for_none(dialect: Dialect) -> None:
    m = ClimbStickMap.for_dialect(dialect)
    assert m.stick_us(0.0) == 1500
    assert m.stick_us(0.002) == 1500 and m.stick_us(-0.002) == 1500
    for want in (0.05, 0.3, 0.5, -0.05, -0.3, -0.5):
        got = m.rate_mps(m.stick_us(want))
        assert got == pytest.approx(want, abs=0.012), want
    assert m.rate_mps(m.stick_us(10.0)) == m.max_up_mps
    assert m.rate_mps(m.stick_us(-10.0)) == -m.max_down_mps


def _est(alt_m: float) -> AltEstimate:
    return AltEstimate(t_s=0.0, alt_m=alt_m, vel_mps=0.0, acc_mps2=0.0, bias_mps2=0.0,
                       sonar_used=True, sonar_status=SonarStatus.USED, innovation_m=0.0,
                       sonar_age_s=0.0, coasting=False, alt_sigma_m=0.01, rejected_total=0)


def test_steady_hold_sits_in_the_dead_zone_and_climbs_slowly_at_most() -> None:
    """At the set point the stick is mid; 8 cm low, the climb asked stays under the blind
    bound ((0.2 m + 0.08 m) in 3.2.1's 5 s before its failsafe)."""
    hold = ClimbRateHold(ClimbRateHoldParams(), ClimbStickMap.for_dialect(Dialect.APM25))
    out = hold.update(1.0, _est(1.0), 0.025)
    assert out.throttle_us == 1500 and out.flown_rate_mps == 0.0
    for _ in range(200):
        out = hold.update(1.0, _est(0.92), 0.025)
    assert 0.0 < out.flown_rate_mps <= 0.28 / 5.0 + 0.005


def test_take_off_is_open_loop_in_the_blind_band_and_stops_when_nothing_rises() -> None:
    p = ClimbRateHoldParams()
    hold = ClimbRateHold(p, ClimbStickMap.for_dialect(Dialect.COPTER4))
    rates = [hold.update(1.0, _est(0.06), 0.025, 0.5, blind=True).flown_rate_mps
             for _ in range(200)]
    assert rates[0] < 0.1 and max(rates) == pytest.approx(0.5, abs=0.02)  # ramped up
    assert hold.blind_exhausted and rates[-1] == 0.0  # 0.75 m asked, nothing seen: stop


def test_taper_reaches_zero_at_the_target() -> None:
    assert sqrt_shape(0.0, 1.0, 0.4) == 0.0
    assert sqrt_shape(1.0, 1.0, 0.4) == pytest.approx((2 * 0.4 * (1.0 - 0.2)) ** 0.5)
    assert sqrt_shape(-0.1, 1.0, 0.4) == pytest.approx(-0.1)


def test_station_toml_chooses_the_hold_mode_and_names_a_bad_one() -> None:
    assert config_from_table({}).hold_mode is HoldMode.THROTTLE
    cfg = config_from_table({"hold_mode": "climb-rate", "climb": {"kp": 2.0}})
    assert cfg.hold_mode is HoldMode.CLIMB_RATE and cfg.climb.kp == 2.0
    with pytest.raises(UsageError, match=r"station.toml: hold_mode: expected one of "
                       r"\['throttle', 'climb-rate'\], got 'alt-hold'"):
        config_from_table({"hold_mode": "alt-hold"}, "station.toml: ")
