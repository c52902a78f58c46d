"""Fast radiation intensity contour maps with one UAV (thesis Chapter 10): the public names.

The concepts live in their own modules: parameters and phases (``radiation_params``), what the
mapper hands out (``radiation_types``), its evidence model (``radiation_evidence``), the sampling
plan (``radiation_mapper``, whose docstring tells the algorithm and its departures from the text),
scoring against the truth (``radiation_score``) and a kinematic run (``radiation_run``).
"""

from planners.radiation_mapper import RadiationMapper, fan_points, sampling_distance_m
from planners.radiation_params import Phase, RadiationMapperParams, Status
from planners.radiation_run import run_radiation, take_reading
from planners.radiation_score import Evaluation, evaluate_region
from planners.radiation_types import Decision, Hotspot, Layer, MapEstimate, RadiationResult

__all__ = [
    "Decision",
    "Evaluation",
    "Hotspot",
    "Layer",
    "MapEstimate",
    "Phase",
    "RadiationMapper",
    "RadiationMapperParams",
    "RadiationResult",
    "Status",
    "evaluate_region",
    "fan_points",
    "run_radiation",
    "sampling_distance_m",
    "take_reading",
]
