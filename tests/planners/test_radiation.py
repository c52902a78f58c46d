"""The Chapter 10 mapper: step API, phases, and whole runs on analytic floors."""

import math

import numpy as np
import pytest

from gcs.mission.kinematic_runs import fly_radiation_field
from planners.radiation import (
    Phase,
    RadiationMapper,
    RadiationMapperParams,
    Status,
    fan_points,
    sampling_distance_m,
)
from planners.radiation.field import RadiationField
from planners.radiation.lawnmower import Interpolation, lawnmower_path, run_lawnmower

# worlds/radiation_3src.toml: a 20 x 20 m floor, three equal sources, background 1 %.
THREE = RadiationField.from_tuples(
    [(-5.0, -4.0, 5000.0), (4.0, -5.0, 5000.0), (1.0, 6.0, 5000.0)], 50.0
)
ONE = RadiationField.from_tuples([(3.0, 2.0, 4000.0)], 40.0)


@pytest.fixture(scope="module")
def three_source_run():
    """One seeded planner run on the thesis's three-source floor."""
    return fly_radiation_field(THREE, RadiationMapperParams(), np.random.default_rng(2026), 400)


def test_three_source_floor_encloses_every_source(three_source_run) -> None:
    r = three_source_run
    assert r.status is Status.REACHED, r.reason
    assert r.sources_enclosed == r.sources_total == 3
    assert r.iou >= 0.85
    assert len(r.contour_polygons) == 3  # three separate hotspot regions
    assert len(r.hotspots) == 3


def test_three_source_run_samples_far_less_than_a_survey(three_source_run) -> None:
    r = three_source_run
    survey_1m = lawnmower_path(1.0, RadiationMapperParams()).shape[0]
    assert r.n_samples < 0.5 * survey_1m
    assert r.explored_fraction < 0.3
    assert r.path_length_m == pytest.approx(
        float(np.sum(np.linalg.norm(np.diff(r.path_n, axis=0), axis=1)))
    )


def test_level_is_a_layer_under_every_hotspot(three_source_run) -> None:
    r = three_source_run
    peaks = [h.peak_cps for h in r.hotspots]
    assert 50.0 < r.level_cps < min(peaks)
    chosen = max(r.layers, key=lambda lay: lay.log_gradient_per_m)
    assert chosen.level_cps == pytest.approx(r.level_cps)
    # Each hotspot found within half a metre of a true source.
    for h in r.hotspots:
        d = np.min(np.linalg.norm(THREE.source_xy_m - np.array(h.pos_n), axis=1))
        assert d < 0.5


def test_maps_are_on_the_floor_grid(three_source_run) -> None:
    r = three_source_run
    assert r.mean_cps.shape == (r.map_ys_m.size, r.map_xs_m.size) == r.log_var.shape
    assert np.all(r.log_var >= 0.0)
    assert r.map_xs_m[0] == -10.0 and r.map_xs_m[-1] == 10.0
    assert r.samples.shape == (r.n_samples, 3)


def test_phases_run_in_order_and_decisions_stay_on_the_floor() -> None:
    rng = np.random.default_rng(4)
    mapper = RadiationMapper(max_samples=300)
    pos = np.array([-9.0, -9.0])
    phases: list[Phase] = []
    while True:
        d = mapper.step(pos, ONE.sample(pos, rng, 1.0))
        if not phases or phases[-1] is not d.phase:
            phases.append(d.phase)
        if d.done:
            break
        assert -10.0 <= d.next_pos_n[0] <= 10.0 and -10.0 <= d.next_pos_n[1] <= 10.0
        pos = np.array(d.next_pos_n)
    assert phases[0] is Phase.LEARNING
    assert phases[-2:] == [Phase.EXECUTING, Phase.DONE]
    assert mapper.status is Status.REACHED
    assert len(mapper.hotspots) == 1
    est = mapper.map_estimate()
    assert est.region.covers(__import__("shapely").Point(3.0, 2.0))
    # After done, further readings change nothing.
    again = mapper.step(pos, 1.0)
    assert again.done and again.samples == d.samples


def test_garbled_readings_are_dropped_and_counted() -> None:
    mapper = RadiationMapper()
    first = mapper.step((-9.0, -9.0), 40.0)
    again = mapper.step((float("nan"), 0.0), 40.0)
    assert again.next_pos_n == first.next_pos_n and again.rejected_readings == 1
    again = mapper.step(first.next_pos_n, -5.0)
    assert again.rejected_readings == 2 and again.samples == 1
    with pytest.raises(ValueError, match="first reading"):
        RadiationMapper().step((0.0, 0.0), float("inf"))


def test_spent_budget_fails_with_a_reason_and_a_real_partial_map() -> None:
    r = fly_radiation_field(ONE, None, np.random.default_rng(1), max_samples=12)
    assert r.status is Status.FAILED
    assert "budget" in r.reason
    assert r.n_samples == 12


def test_fan_is_spread_over_the_field_of_view() -> None:
    p = RadiationMapperParams()
    fan = fan_points(np.array([0.0, 0.0]), 0.0, 2.0, p)
    np.testing.assert_allclose(np.linalg.norm(fan, axis=1), 2.0)
    angles = np.degrees(np.arctan2(fan[:, 1], fan[:, 0]))
    np.testing.assert_allclose(angles, [-72.0, -36.0, 0.0, 36.0, 72.0])
    clipped = fan_points(np.array([9.5, 0.0]), 0.0, 2.0, p)
    assert np.all(clipped[:, 0] <= 10.0)


def test_sampling_distance_shrinks_as_intensity_grows() -> None:
    p = RadiationMapperParams()
    d = [sampling_distance_m(i, 50.0, p) for i in (50.0, 200.0, 800.0, 1e6)]
    assert d[0] == pytest.approx(p.k1_gain_m)
    assert d[1] == pytest.approx(p.k1_gain_m / 2.0)
    assert d[0] > d[1] > d[2] >= d[3] == p.min_sample_distance_m


def test_lawnmower_is_a_boustrophedon_and_converges_with_spacing() -> None:
    p = RadiationMapperParams()
    path = lawnmower_path(2.0, p)
    assert path.shape == (121, 2)
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    np.testing.assert_allclose(steps, 2.0)  # no diagonal jumps between rows
    level = 0.4 * ONE.intensity_at((3.0, 2.0))
    coarse = run_lawnmower(ONE, 2.0, level, np.random.default_rng(0))
    fine = run_lawnmower(ONE, 0.5, level, np.random.default_rng(0))
    assert fine.iou > coarse.iou and fine.iou > 0.9
    assert fine.sources_enclosed == 1 and fine.explored_fraction == 1.0
    with pytest.raises(ValueError):
        run_lawnmower(ONE, 0.0, level, np.random.default_rng(0))


def test_bad_parameters_are_rejected() -> None:
    with pytest.raises(ValueError):
        RadiationMapperParams(x_min_m=5.0, x_max_m=5.0)
    with pytest.raises(ValueError):
        RadiationMapperParams(layer_ratio=1.5)
    with pytest.raises(ValueError):
        RadiationMapper(max_samples=0)
    assert math.isclose(RadiationMapperParams().floor_area_m2, 400.0)


def test_five_sources_of_unequal_strength_are_all_enclosed() -> None:
    field = RadiationField.from_tuples(
        [(-6.0, -6.0, 3000.0), (5.0, -6.5, 7000.0), (0.5, 0.0, 4500.0), (-6.0, 5.5, 6000.0),
         (6.0, 6.0, 2600.0)],
        70.0,
    )  # fmt: skip
    r = fly_radiation_field(field, None, np.random.default_rng(5), 400)
    assert r.status is Status.REACHED, r.reason
    assert r.sources_enclosed == 5 and len(r.hotspots) == 5
    assert r.iou >= 0.85
    assert r.level_cps < min(h.peak_cps for h in r.hotspots)


def test_run_needs_room_for_a_map() -> None:
    with pytest.raises(ValueError, match="max_samples"):
        fly_radiation_field(ONE, None, np.random.default_rng(0), max_samples=1)


def test_a_floor_without_a_hotspot_fails_and_says_why() -> None:
    faint = RadiationField.from_tuples([(0.0, 0.0, 20.0)], 50.0)
    r = fly_radiation_field(faint, None, np.random.default_rng(3), 400)
    assert r.status is Status.FAILED
    assert "no hotspot" in r.reason
    assert r.hotspots == ()


def test_parameters_load_from_a_toml_table() -> None:
    import tomllib

    table = tomllib.loads(
        "x_min_m = 0.0\nx_max_m = 20.0\nk1_gain_m = 2.5\nsamples_per_fan = 5\n"
        "gp_lengthscales_m = [1.0, 2.0]\n"
    )
    p = RadiationMapperParams.from_toml(table)
    assert (p.x_min_m, p.x_max_m, p.k1_gain_m, p.gp_lengthscales_m) == (0.0, 20.0, 2.5, (1.0, 2.0))
    for bad in ({"k1_gain": 1.0}, {"k1_gain_m": "far"}, {"samples_per_fan": 4.5},
                {"gp_lengthscales_m": 2.0}, {"dwell_s": True}):  # fmt: skip
        with pytest.raises(ValueError):
            RadiationMapperParams.from_toml(bad)


def test_executing_samples_follow_the_chosen_layer(three_source_run) -> None:
    r = three_source_run
    assert len(r.sample_phases) == r.n_samples
    on_trace = np.array([ph is Phase.EXECUTING for ph in r.sample_phases])
    assert on_trace.sum() >= 3 * 6  # each hotspot's loop took several steps
    xy = r.samples[on_trace, :2]
    true_log_ratio = np.log(THREE.intensity(xy[:, 0], xy[:, 1]) / r.level_cps)
    # Zig-zagging across the contour, but close to it: within a factor 2 almost always.
    assert np.mean(np.abs(true_log_ratio) < math.log(2.0)) > 0.8
    assert abs(np.median(true_log_ratio)) < 0.3


def test_gp_mapped_lawnmower_beats_log_linear_at_coarse_spacing() -> None:
    level = 0.4 * ONE.intensity_at((3.0, 2.0))
    linear = run_lawnmower(ONE, 2.0, level, np.random.default_rng(1))
    gp = run_lawnmower(ONE, 2.0, level, np.random.default_rng(1), None, Interpolation.GP)
    assert gp.n_samples == linear.n_samples == 121
    assert gp.iou > linear.iou
    assert gp.mean_cps.shape == (101, 101) and np.all(gp.log_var >= 0.0)
    assert "gp map" in gp.reason


def test_counting_to_a_target_cuts_the_dwell_and_still_maps_every_source() -> None:
    p = RadiationMapperParams(target_counts=800)
    r = fly_radiation_field(THREE, p, np.random.default_rng(2026), 400)
    assert r.status is Status.REACHED, r.reason
    assert r.sources_enclosed == 3 and r.iou >= 0.85
    mapper = RadiationMapper(p)
    first = mapper.step((-9.0, -9.0), 200.0, dwell_s=1.0)
    # a reading with a dwell that is not a positive time is dropped and counted
    again = mapper.step(first.next_pos_n, 2500.0, dwell_s=0.0)
    assert again.rejected_readings == 1 and again.samples == 1
    with pytest.raises(ValueError, match="target_counts"):
        RadiationMapperParams(target_counts=-1.0)
    with pytest.raises(ValueError, match="detector_window_s"):
        RadiationMapperParams(detector_window_s=2.0)


def test_a_short_dwell_weighs_less_in_the_model() -> None:
    # the same reading counted 0.2 s instead of 1 s is five times fewer counts: noisier, so the
    # model's uncertainty there is larger
    stds = []
    for dwell in (1.0, 0.2):
        mapper = RadiationMapper()
        pts = [(-9.0, -9.0), (-6.0, -9.0), (-9.0, -6.0), (-6.0, -6.0)]
        for k, q in enumerate(pts):
            mapper.step(q, 300.0 + 10.0 * k, dwell_s=dwell)
        est = mapper.map_estimate()
        ix = int(np.argmin(np.abs(est.xs_m + 6.0)))
        iy = int(np.argmin(np.abs(est.ys_m + 6.0)))
        stds.append(float(est.log_var[iy, ix]))
    assert stds[1] > stds[0]


def test_no_climb_is_spent_on_readings_a_known_source_explains() -> None:
    # bench/radiation.py --seed 7, field 17: the first climb from the corner runs out of fans
    # half a metre short of its source; the contour traced round it must not then look like a
    # new hotspot (a 20-sample climb that found nothing)
    field = RadiationField.from_tuples(
        [(-1.4157, 4.2245, 6510.18), (5.0435, 3.6798, 6888.46), (-6.1887, 6.6137, 5116.52)],
        68.88,
    )
    rng = np.random.default_rng(132854973)
    mapper = RadiationMapper(RadiationMapperParams())
    pos = np.array([-9.0, -9.0])
    checks = 0
    while True:
        d = mapper.step(pos, field.sample(pos, rng, 1.0))
        checks += d.reason == "checking a possible hotspot"
        if d.done:
            break
        pos = np.array(d.next_pos_n)
    assert mapper.status is Status.REACHED and len(mapper.hotspots) == 3
    assert checks == 2  # one per source after the first, none wasted
